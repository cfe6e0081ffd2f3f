// Rig calibrations that tests make from the shipped ones (rigs.py for the Node tests).
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const SOURCE = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..", "..");

// calib/paper_rig.calib.json: the paper's rig, the default of every graph.
export function paperRigPath() {
  return path.join(SOURCE, "calib", "paper_rig.calib.json");
}

// calib/field_rig.calib.json: another rig, its colour camera rotated and offset.
export function fieldRigPath() {
  return path.join(SOURCE, "calib", "field_rig.calib.json");
}

// The paper's rig at a quarter of its resolution, the same fields of view, written into
// `folder`; returns its path.
export function quarterRig(folder) {
  const rig = JSON.parse(fs.readFileSync(paperRigPath()));
  for (const camera of [rig.depth_camera, rig.color_camera]) {
    camera.width /= 4;
    camera.height /= 4;
    for (const key of ["fx", "fy", "cx", "cy"]) camera[key] /= 4;
  }
  const file = path.join(folder, "quarter.calib.json");
  fs.writeFileSync(file, JSON.stringify(rig, null, 2));
  return file;
}
