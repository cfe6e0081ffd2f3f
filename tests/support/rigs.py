"""Rig calibrations that tests make from the shipped ones."""
import json
import os

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def paper_rig_path():
    """calib/paper_rig.calib.json: the paper's rig, the default of every graph."""
    return os.path.join(SOURCE, "calib", "paper_rig.calib.json")


def field_rig_path():
    """calib/field_rig.calib.json: another rig, its colour camera rotated, offset in three
    axes and with lens distortion."""
    return os.path.join(SOURCE, "calib", "field_rig.calib.json")


def quarter_rig(folder, source=None, name="quarter.calib.json"):
    """A rig (the paper's by default) at a quarter of its resolution: fast to simulate,
    same views."""
    with open(source or paper_rig_path()) as f:
        rig = json.load(f)
    for camera in (rig["depth_camera"], rig["color_camera"]):
        camera["width"] //= 4
        camera["height"] //= 4
        for key in ("fx", "fy", "cx", "cy"):
            camera[key] /= 4
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        json.dump(rig, f, indent=2)
    return path
