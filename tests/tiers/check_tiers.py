#!/usr/bin/env python3
"""The source tree's dependency rules (docs/development.md), checked on every quoted
#include, every path a CMakeLists.txt names and every target it links:

  plugins/P -> libs, sdk          (never another plugin)
  libs/L    -> libs, sdk
  tools/T   -> tools, framework, libs, sdk
  framework -> sdk;  sdk -> sdk
  tests/T   -> anything but another test folder (shared helpers live in tests/support)

Prints each violation with the file and line, and exits 1 if there is one."""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "../.."))
FOLDERS = ("sdk", "framework", "libs", "plugins", "tools", "tests", "bench", "fuzz")
SOURCE = (".h", ".hpp", ".cpp")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
CMAKE_PATH = re.compile(r"\$\{(?:PROJECT|CMAKE)_SOURCE_DIR\}/([\w./-]+)")
CMAKE_CALL = re.compile(r"\b(\w+)\s*\(([^()]*)\)", re.S)
# How each call names the targets it defines, and where its linked targets start.
DEFINES = {"add_library": "{}", "add_executable": "{}", "tilth_add_kernel_levels": "{}",
           "tilth_add_lib": "tilth_lib_{}", "tilth_add_plugin": "tilth_{}"}
KEYWORDS = {"SOURCES", "STAGES", "DISPATCH", "LIBRARIES", "PUBLIC", "PRIVATE", "INTERFACE"}


def unit(path):
    """The part of the tree a file belongs to: ('plugins', 'depth'), ('sdk', None), ..."""
    parts = os.path.relpath(path, ROOT).split(os.sep)
    if parts[0] in ("plugins", "libs", "tools", "tests") and len(parts) > 2:
        return parts[0], parts[1]
    return parts[0], None


def allowed(source, target):
    (tier, name), (to_tier, to_name) = source, target
    if source == target:
        return True
    if tier in ("bench", "fuzz"):
        return to_tier != "tests" or to_name == "support"
    if tier == "tests":
        return to_tier != "tests" or to_name == "support"
    return to_tier in {
        "sdk": {"sdk"},
        "framework": {"sdk", "framework"},
        "libs": {"sdk", "libs"},
        "plugins": {"sdk", "libs"},
        "tools": {"sdk", "framework", "libs", "tools"},
    }[tier]


def tree_files():
    for folder in FOLDERS:
        for directory, subdirs, files in os.walk(os.path.join(ROOT, folder)):
            subdirs[:] = [d for d in subdirs if d not in ("node_modules", "__pycache__")]
            for name in files:
                yield os.path.join(directory, name)


def cmake_calls(path):
    """(line, command, arguments) of every call in a CMakeLists.txt, comments left out."""
    with open(path, encoding="utf-8") as text:
        content = re.sub(r"#[^\n]*", "", text.read())
    for match in CMAKE_CALL.finditer(content):
        line = content.count("\n", 0, match.start()) + 1
        yield line, match.group(1), match.group(2).split()


def linked(command, arguments):
    """The targets a call links: every argument of target_link_libraries after the target,
    the LIBRARIES of the project's own functions."""
    if command == "target_link_libraries":
        return [a for a in arguments[1:] if a not in KEYWORDS]
    if command in DEFINES and "LIBRARIES" in arguments:
        rest = arguments[arguments.index("LIBRARIES") + 1:]
        return [a for a in rest if a not in KEYWORDS]
    return []


def target_units(cmake_files):
    """Which part of the tree defines each target."""
    units = {}
    for path in cmake_files:
        for _, command, arguments in cmake_calls(path):
            if command in DEFINES and arguments:
                name = DEFINES[command].format(arguments[0])
                units[name] = unit(path)
                if command == "tilth_add_plugin" and "STAGES" in arguments:
                    units[name + "_stages"] = unit(path)
    return units


def main():
    files = list(tree_files())
    by_suffix = {}
    for path in files:
        if path.endswith(SOURCE):
            relative = os.path.relpath(path, ROOT).split(os.sep)
            for i in range(len(relative)):
                by_suffix.setdefault("/".join(relative[i:]), []).append(path)

    problems = []
    for path in files:
        name = os.path.basename(path)
        if not (path.endswith(SOURCE) or name == "CMakeLists.txt"):
            continue
        source = unit(path)
        with open(path, encoding="utf-8") as text:
            for number, line in enumerate(text, 1):
                targets = []
                if name == "CMakeLists.txt":
                    targets = [os.path.join(ROOT, p) for p in CMAKE_PATH.findall(line)]
                elif match := INCLUDE.match(line):
                    included = match.group(1)
                    beside = os.path.normpath(os.path.join(os.path.dirname(path), included))
                    if os.path.exists(beside):
                        targets = [beside]
                    else:
                        # Found through an include directory: ambiguous names must agree.
                        targets = by_suffix.get(included, [])[:1]
                for target in targets:
                    if not os.path.relpath(target, ROOT).startswith(FOLDERS):
                        continue
                    if not allowed(source, unit(target)):
                        where = os.path.relpath(path, ROOT)
                        what = os.path.relpath(target, ROOT)
                        problems.append(f"{where}:{number}: {'/'.join(filter(None, source))} "
                                        f"must not depend on {what}")
    cmake_files = [p for p in files if os.path.basename(p) == "CMakeLists.txt"]
    units = target_units(cmake_files)
    for path in cmake_files:
        source = unit(path)
        for line, command, arguments in cmake_calls(path):
            for target in linked(command, arguments):
                if target in units and not allowed(source, units[target]):
                    problems.append(f"{os.path.relpath(path, ROOT)}:{line}: "
                                    f"{'/'.join(filter(None, source))} must not link {target} "
                                    f"({'/'.join(filter(None, units[target]))})")
    for problem in problems:
        print(problem)
    print(f"{len(problems)} dependency rule violation(s)" if problems
          else "the tiers' dependency rules hold")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
