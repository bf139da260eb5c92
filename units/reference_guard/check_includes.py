#!/usr/bin/env python3
"""The include graph of target saarcor_units_reference, read from the compiler.

    check_includes.py BUILD/compile_commands.json

Takes the compile command of units/reference_model.cpp as the build runs it and reruns it with -M
(the headers it reads). Passes when the command carries the guard (reference_guard/ on the quote
include path), the headers include the unit semantics and the reference policy and neither
units/fast_paths.h nor units/fast_datapath.h; and when the same command, given a file that
includes units/fast_datapath.h, stops at the guard's #error (the guard bites). Exit 1 otherwise,
naming what failed.
"""
import json
import os
import shlex
import subprocess
import sys

GUARD = os.path.dirname(os.path.abspath(__file__))
SOURCE = "units/reference_model.cpp"
MUST = ["units/reference_datapath.h", "units/traversal_step.h", "units/rgs_step.h",
        "units/datapath.h", "units/lane_values.h"]
MUST_NOT = ["units/fast_paths.h", "units/fast_datapath.h"]


def compile_args(db_path):
    with open(db_path, encoding="utf-8") as f:
        db = json.load(f)
    for e in db:
        if e["file"].endswith(SOURCE):
            args = e["arguments"] if "arguments" in e else shlex.split(e["command"])
            return args, e["directory"]
    sys.exit(f"check_includes: {SOURCE} not in {db_path}")


def strip_output(args):
    """The command without its output options (-o, -c and the depfile's -MD/-MT/-MF)."""
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
        elif a in ("-o", "-MT", "-MF", "-MQ"):
            skip = True
        elif a not in ("-c", "-MD", "-MMD"):
            out.append(a)
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    args, cwd = compile_args(sys.argv[1])
    failed = []
    cmd = strip_output(args)
    if f"-iquote {GUARD}" not in " ".join(cmd):
        failed.append(f"the command lacks -iquote {GUARD}")
    run = subprocess.run(cmd + ["-M"], cwd=cwd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        failed.append("the reference translation unit does not preprocess:\n" + run.stderr)
    deps = run.stdout.replace("\\\n", " ").split()
    for h in MUST:
        if not any(d.endswith(h) for d in deps):
            failed.append(f"{h} is not in the include graph")
    for h in MUST_NOT:
        hits = [d for d in deps if d.endswith(h)]
        if hits:
            failed.append(f"{h} is in the include graph: {hits[0]}")
    # The guard bites: a header that reaches the fast paths does not compile in this target.
    src = [a for a in cmd if a.endswith(SOURCE)]
    probe = [a for a in cmd if a not in src] + ["-fsyntax-only", "-x", "c++", "-"]
    run = subprocess.run(probe, cwd=cwd, input='#include "units/fast_datapath.h"\n',
                         capture_output=True, text=True, check=False)
    if run.returncode == 0 or "includes units/fast_paths.h" not in run.stderr:
        failed.append("a file including units/fast_datapath.h compiles in this target")
    for f in failed:
        print("check_includes: " + f)
    if failed:
        sys.exit(1)
    print(f"check_includes: {SOURCE}: {len(deps) - 2} headers, no fast path; the guard bites")


if __name__ == "__main__":
    main()
