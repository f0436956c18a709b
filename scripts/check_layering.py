#!/usr/bin/env python3
"""The pipeline's order, enforced (docs/architecture.md; issue #32).

Every module of the library is a folder, include/robomill/<module>/ for its
public headers and src/<module>/ for its implementation. A module may include
the headers of the modules before it in MODULES and its own, never one after
it: the numerical modules never see a file format, the job or anything that
runs a command. apps/ and python/ sit after every module.

    scripts/check_layering.py [ROOT]

prints every include against the order (file, line, what it includes, why it
may not) and exits 1 if there is one; a folder under src/ or
include/robomill/ that is not in MODULES is an error too, so a new module must
be given its place. A command's source (src/commands/) includes only core,
io, job, analysis, report and commands: its numbers come from an analysis.
`make test` runs it (ctest: layering.includes), and
layering.detects_a_wrong_include checks that it catches a planted one.
"""
import os
import re
import sys

# The pipeline, first to last. Each entry: module, what it is.
MODULES = [
    ("core", "errors, parallel map, random numbers, text helpers"),
    ("uncertainty", "distributions, quasi-random draws, sample statistics"),
    ("monitoring", "spectra and the chatter verdict of a signal"),
    ("dynamics", "modal models, FRFs, modal fitting"),
    ("robot", "kinematics, stiffness, joint-space dynamics, posture interpolation"),
    ("tool", "cutter geometry and edge elements"),
    ("cutting", "force laws, engagement, milling forces"),
    ("toolpath", "program moves, dexel stock, material removal, engagement along a program"),
    ("deflection", "tool and robot deformation, contact boundary"),
    ("stability", "regenerative model, zero-order, Floquet (SDM/FDM), lobes"),
    ("simulation", "time-domain simulation with material removal"),
    ("surface", "Z-map topography and roughness"),
    ("planning", "workpiece placement, pose optimization, cutting advice"),
    ("robot_path", "the robot along the program: postures, margins, feeds, compensation"),
    ("atlas", "the workspace atlas and its result store"),
    ("learning", "likelihoods of test cuts, the tempered SMC sampler, expected information"),
    ("io", "file formats: programs, FRFs, recordings, CSV, summaries"),
    ("job", "the Job description, its schema, units, YAML parsing, --set"),
    ("analysis", "job-level analyses: one typed entry point per question"),
    ("report", "report.html"),
    ("commands", "each command: compute, then write"),
]
RANK = {name: i for i, (name, _) in enumerate(MODULES)}

# A command computes nothing itself: its numbers come from one typed analysis
# (analysis/), and the numerical types it formats reach it through that
# analysis's header. So a command's source may include only these modules.
COMMAND_MAY_INCLUDE = ("core", "io", "job", "analysis", "report", "commands")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]robomill/([A-Za-z0-9_]+)/([^>"]+)[>"]')


def module_of(root, path):
    rel = os.path.relpath(path, root).split(os.sep)
    if rel[0] == "include" and len(rel) > 3 and rel[1] == "robomill":
        return rel[2]
    if rel[0] == "src" and len(rel) > 2:
        return rel[1]
    return None


def check(root):
    problems = []
    for top in ("include/robomill", "src"):
        base = os.path.join(root, top)
        if not os.path.isdir(base):
            continue
        for folder in sorted(os.listdir(base)):
            if os.path.isdir(os.path.join(base, folder)) and folder not in RANK:
                problems.append(f"{top}/{folder}/: a module not in the pipeline's order "
                                f"(scripts/check_layering.py MODULES; docs/architecture.md)")
        for dirpath, _, files in os.walk(base):
            for name in sorted(files):
                if not name.endswith((".hpp", ".cpp", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                module = module_of(root, path)
                if module not in RANK:
                    continue
                with open(path, encoding="utf-8") as source:
                    for number, line in enumerate(source, 1):
                        found = INCLUDE.match(line)
                        if not found:
                            continue
                        target = found.group(1)
                        rel = os.path.relpath(path, root)
                        if target not in RANK:
                            problems.append(f"{rel}:{number}: includes robomill/{target}/"
                                            f"{found.group(2)}, a module not in the order")
                        elif RANK[target] > RANK[module]:
                            problems.append(
                                f"{rel}:{number}: {module} includes robomill/{target}/"
                                f"{found.group(2)}, but {target} ({MODULES[RANK[target]][1]}) "
                                f"comes after {module} in the pipeline")
                        elif (module == "commands" and top == "src"
                              and target not in COMMAND_MAY_INCLUDE):
                            problems.append(
                                f"{rel}:{number}: the command includes robomill/{target}/"
                                f"{found.group(2)}: a command formats what its analysis "
                                f"(robomill/analysis/) returns and includes only "
                                f"{', '.join(COMMAND_MAY_INCLUDE)}")
    return problems


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    problems = check(os.path.abspath(root))
    for problem in problems:
        print(problem)
    if problems:
        print(f"layering: {len(problems)} include(s) against the pipeline's order")
        return 1
    print(f"layering: {len(MODULES)} modules, every include in order")
    return 0


if __name__ == "__main__":
    sys.exit(main())
