#!/usr/bin/python3
"""Checks a Chrome trace-event JSON file (what Perfetto's UI and chrome://tracing open) against the
format's rules, independently of the writer (saarcor render --perfetto, units/perfetto_trace.cpp):
Python's json module reads it and this script knows nothing of how it was made.

Rules (the Trace Event Format document, as the viewers apply it):
  - the file is an object with a "traceEvents" list (or a bare list of events);
  - every event has a known "ph", an integer "pid" and "tid", and (but metadata) a numeric "ts";
  - "B"/"E" nest per track (pid, tid): each E closes the track's open B, none left open;
  - "X" has a numeric "dur" >= 0, and the X slices of one track nest (disjoint or contained);
  - timestamps do not go back on a track, in file order;
  - "C" (counter) has a non-empty "args" whose values are all numbers;
  - flow events ("s", "t", "f") carry an "id"; each id has one start and one finish, the finish
    not before the start, and each lies inside a slice of its track (the slice it binds to);
  - "M" (metadata) names a known kind and has "args"; every process with events is named.

usage: check_trace_events.py FILE.json [--require X,C,s,f] [--min-slices N]
       check_trace_events.py --self-test
Prints a summary line; exit 0 when every rule holds, 1 with one line per broken rule (at most 20).
"""
import argparse
import bisect
import json
import sys

PHASES = set("BEXiICMsftbenNODPpRrAacT(") | {"I"}
METADATA = {"process_name", "process_labels", "process_sort_index", "thread_name",
            "thread_sort_index"}


def is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def events_of(doc, errors):
    if isinstance(doc, list):
        return doc
    if isinstance(doc, dict) and isinstance(doc.get("traceEvents"), list):
        return doc["traceEvents"]
    errors.append("the file is neither a list of events nor an object with a traceEvents list")
    return []


def check_fields(i, e, errors):
    if not isinstance(e, dict):
        errors.append(f"event {i}: not an object")
        return False
    ph = e.get("ph")
    if ph not in PHASES:
        errors.append(f"event {i}: unknown ph {ph!r}")
        return False
    for key in ("pid", "tid"):
        if not isinstance(e.get(key), int) or isinstance(e.get(key), bool):
            errors.append(f"event {i} ({ph}): {key} missing or not an integer")
            return False
    if ph != "M" and (not is_number(e.get("ts")) or e["ts"] < 0):
        errors.append(f"event {i} ({ph}): ts missing, not a number or negative")
        return False
    return True


def check_slices(tracks_x, errors):
    """X slices of each track nest: sorted by start (longest first), each lies inside the open
    enclosing slice or starts after it ends."""
    eps = 1e-6
    for track, xs in tracks_x.items():
        stack = []
        for ts, dur, i in sorted(xs, key=lambda s: (s[0], -s[1], s[2])):
            while stack and ts >= stack[-1][0] + stack[-1][1] - eps:
                stack.pop()
            if stack and ts + dur > stack[-1][0] + stack[-1][1] + eps:
                errors.append(f"event {i}: X slice [{ts}, {ts + dur}] on track {track} overlaps "
                              f"event {stack[-1][2]} [{stack[-1][0]}, "
                              f"{stack[-1][0] + stack[-1][1]}] without nesting")
                break
            stack.append((ts, dur, i))


def inside_slice(tracks_x, track, ts):
    xs = sorted(tracks_x.get(track, []))
    k = bisect.bisect_right(xs, (ts, float("inf"), float("inf")))
    return any(s[0] <= ts + 1e-6 and ts <= s[0] + s[1] + 1e-6 for s in xs[max(0, k - 64):k])


def check_flows(flows, tracks_x, errors):
    for fid, ends in flows.items():
        starts = [e for e in ends if e[0] == "s"]
        finishes = [e for e in ends if e[0] == "f"]
        if len(starts) != 1 or len(finishes) != 1:
            errors.append(f"flow id {fid}: {len(starts)} starts and {len(finishes)} finishes "
                          "(one of each expected)")
            continue
        if finishes[0][1] < starts[0][1]:
            errors.append(f"flow id {fid}: finishes at {finishes[0][1]} before it starts at "
                          f"{starts[0][1]}")
        for ph, ts, track, i in ends:
            if not inside_slice(tracks_x, track, ts):
                errors.append(f"event {i}: flow {ph} of id {fid} at {ts} lies in no slice of "
                              f"track {track}")


def check_event(i, e, state, errors):
    ph, track = e["ph"], (e["pid"], e["tid"])
    state["count"][ph] = state["count"].get(ph, 0) + 1
    if ph == "M":
        if e.get("name") not in METADATA or not isinstance(e.get("args"), dict):
            errors.append(f"event {i}: metadata {e.get('name')!r} unknown or without args")
        elif e["name"] == "process_name":
            state["named"].add(e["pid"])
        return
    state["pids"].add(e["pid"])
    last = state["last_ts"].get(track)
    if last is not None and e["ts"] < last:
        errors.append(f"event {i}: ts {e['ts']} goes back on track {track} (after {last})")
    state["last_ts"][track] = e["ts"]
    if ph == "B":
        state["open"].setdefault(track, []).append(i)
    elif ph == "E":
        if not state["open"].get(track):
            errors.append(f"event {i}: E on track {track} without an open B")
        else:
            state["open"][track].pop()
    elif ph == "X":
        if not is_number(e.get("dur")) or e["dur"] < 0:
            errors.append(f"event {i}: X without a numeric dur >= 0")
        else:
            state["x"].setdefault(track, []).append((e["ts"], e["dur"], i))
    elif ph == "C":
        args = e.get("args")
        if not isinstance(args, dict) or not args or not all(is_number(v) for v in args.values()):
            errors.append(f"event {i}: counter args empty or not all numbers: {args!r}")
    elif ph in "stf":
        if "id" not in e:
            errors.append(f"event {i}: flow event {ph} without an id")
        else:
            state["flows"].setdefault((e.get("cat"), e["id"]), []).append(
                ("s" if ph == "s" else "f" if ph == "f" else "t", e["ts"], track, i))


def check(doc):
    errors = []
    state = {"last_ts": {}, "open": {}, "x": {}, "flows": {}, "named": set(), "pids": set(),
             "count": {}}
    for i, e in enumerate(events_of(doc, errors)):
        if check_fields(i, e, errors):
            check_event(i, e, state, errors)
    for track, opened in state["open"].items():
        if opened:
            errors.append(f"track {track}: {len(opened)} B events never closed")
    check_slices(state["x"], errors)
    check_flows(state["flows"], state["x"], errors)
    for pid in sorted(state["pids"] - state["named"]):
        errors.append(f"process {pid} has events but no process_name")
    return errors, state["count"], len(state["flows"])


def self_test():
    """Each rule above rejects a file that breaks it, and a good file passes."""
    def doc(*evs):
        return {"traceEvents": [{"ph": "M", "name": "process_name", "pid": 1, "tid": 0,
                                 "args": {"name": "p"}}] + list(evs)}
    x = {"ph": "X", "name": "a", "pid": 1, "tid": 1, "ts": 1.0, "dur": 2.0}
    good = doc(x, {"ph": "s", "id": 1, "cat": "m", "name": "m", "pid": 1, "tid": 1, "ts": 1.2},
               {"ph": "X", "name": "b", "pid": 1, "tid": 1, "ts": 1.5, "dur": 0.5},
               {"ph": "f", "bp": "e", "id": 1, "cat": "m", "name": "m", "pid": 1, "tid": 1,
                "ts": 2.0},
               {"ph": "C", "name": "q", "pid": 1, "tid": 0, "ts": 3.0, "args": {"n": 4}},
               {"ph": "B", "name": "c", "pid": 1, "tid": 2, "ts": 3.0},
               {"ph": "E", "name": "c", "pid": 1, "tid": 2, "ts": 4.0})
    bad = {
        "unknown ph": doc(dict(x, ph="Q")),
        "no tid": doc({k: v for k, v in x.items() if k != "tid"}),
        "no dur": doc({k: v for k, v in x.items() if k != "dur"}),
        "ts back": doc(x, dict(x, ts=0.5)),
        "overlap": doc(x, dict(x, ts=2.0, dur=2.0)),
        "counter text": doc({"ph": "C", "name": "q", "pid": 1, "tid": 0, "ts": 1, "args":
                             {"n": "4"}}),
        "open B": doc({"ph": "B", "name": "c", "pid": 1, "tid": 2, "ts": 3.0}),
        "lone E": doc({"ph": "E", "name": "c", "pid": 1, "tid": 2, "ts": 3.0}),
        "unpaired flow": doc(x, {"ph": "s", "id": 7, "cat": "m", "name": "m", "pid": 1, "tid": 1,
                                 "ts": 1.2}),
        "flow outside a slice": doc(x, {"ph": "s", "id": 7, "cat": "m", "name": "m", "pid": 1,
                                        "tid": 1, "ts": 1.2},
                                    {"ph": "f", "id": 7, "cat": "m", "name": "m", "pid": 1,
                                     "tid": 1, "ts": 9.0}),
        "unnamed process": doc(dict(x, pid=2)),
    }
    failures = []
    if check(good)[0]:
        failures.append("the good file fails: " + "; ".join(check(good)[0]))
    for what, d in bad.items():
        if not check(d)[0]:
            failures.append(f"a file with {what} passes")
    for f in failures:
        print("self-test: " + f)
    print(f"self-test: {len(bad)} broken files rejected, good file accepted"
          if not failures else f"self-test: {len(failures)} failures")
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", nargs="?")
    ap.add_argument("--require", default="", help="ph types that must occur, e.g. X,C,s,f")
    ap.add_argument("--min-slices", type=int, default=0, help="at least this many X slices")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if not a.file:
        ap.error("give FILE.json or --self-test")
    try:
        with open(a.file, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        print(f"{a.file}: not readable as JSON: {e}")
        return 1
    errors, count, flows = check(doc)
    for ph in filter(None, a.require.split(",")):
        if count.get(ph, 0) == 0:
            errors.append(f"no {ph} event (required)")
    if count.get("X", 0) < a.min_slices:
        errors.append(f"{count.get('X', 0)} X slices, fewer than {a.min_slices}")
    summary = ", ".join(f"{k} {v}" for k, v in sorted(count.items()))
    print(f"{a.file}: {summary}; {flows} flows; {len(errors)} rule(s) broken")
    for e in errors[:20]:
        print("  " + e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
