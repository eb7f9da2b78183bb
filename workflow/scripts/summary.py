#!/usr/bin/python3
"""The all-takes table of the arco workflow: OUT/summary.tsv and OUT/summary.md.

usage: summary.py OUT TAKE:STAGE,STAGE,... [...] [--report-failures]

One row per take from OUT/TAKE/result/result.json and OUT/TAKE/eval.json. A take whose
stage left no output failed there (its log OUT/TAKE/logs/STAGE.log names the error) or
has not run yet (no log). --report-failures also prints one line per failed take to
stderr. Standard library only (Debian's python3).
"""
import json
import os
import sys

COLUMNS = [
    "take", "status", "stage", "frames", "views", "voiced_pct", "pressed", "open_string",
    "rest", "uncertain", "corrected", "out_of_reach", "hand_mpjpe_mm", "contact_mm",
    "string_acc", "finger_acc", "rpa50", "message",
]


def stage_output(out, take, stage):
    if stage == "eval":
        return os.path.join(out, take, "eval.json")
    return os.path.join(out, take, "result" if stage == "run" else stage)


def error_line(log):
    """The log's `arco: error:` line, else its last non-empty line."""
    try:
        with open(log, errors="replace") as f:
            lines = [line.strip() for line in f if line.strip()]
    except OSError:
        return ""
    errors = [line for line in lines if line.startswith("arco: error:")]
    if errors:
        return errors[-1]
    return lines[-1] if lines else "failed without a message"


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def fmt(value, digits=2):
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def take_row(out, take, stages):
    row = {"take": take, "status": "ok", "stage": "", "message": ""}
    for stage in stages:
        if os.path.exists(stage_output(out, take, stage)):
            continue
        log = os.path.join(out, take, "logs", stage + ".log")
        if os.path.exists(log):
            row.update(status="failed", stage=stage, message=error_line(log))
        else:
            row.update(status="not run", stage=stage)
        break
    # A result left from an earlier run counts only when no stage up to `run` failed now.
    run_done = not row["stage"] or stages.index(row["stage"]) > stages.index("run")
    result = read_json(os.path.join(out, take, "result", "result.json")) if run_done else None
    if result:
        stage_info = result.get("stages", {})
        row["frames"] = result.get("frames", {}).get("count")
        row["views"] = len(result.get("cameras", []))
        voiced = stage_info.get("pitch", {}).get("summary", {}).get("voiced_fraction")
        row["voiced_pct"] = fmt(100 * voiced, 1) if voiced is not None else ""
        refined = stage_info.get("arco", {}).get("summary", {})
        for key, name in (("pressed", "pressed"), ("open_string", "open_string"),
                          ("rest", "rest"), ("uncertain", "uncertain"),
                          ("corrected", "corrected_frames"),
                          ("out_of_reach", "rejected_out_of_reach")):
            row[key] = fmt(refined.get(name))
    evaluation = read_json(os.path.join(out, take, "eval.json"))
    if evaluation and row["status"] == "ok":
        arco = evaluation.get("methods", {}).get("arco", {})
        row["hand_mpjpe_mm"] = fmt(arco.get("mpjpe_hand_mm"))
        row["contact_mm"] = fmt(arco.get("contact_deviation_mm"))
        row["string_acc"] = fmt(arco.get("string_accuracy"), 3)
        row["finger_acc"] = fmt(arco.get("finger_accuracy"), 3)
        row["rpa50"] = fmt((evaluation.get("pitch") or {}).get("rpa50"), 3)
    return {c: str(row.get(c, "") if row.get(c) is not None else "") for c in COLUMNS}


def write_atomic(path, text):
    tmp = f"{os.path.dirname(path)}/.tmp-{os.getpid()}.{os.path.basename(path)}"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main(argv):
    report = "--report-failures" in argv
    args = [a for a in argv if a != "--report-failures"]
    if len(args) < 2:
        sys.exit(__doc__)
    out = args[0]
    rows = []
    for spec in args[1:]:
        take, _, stages = spec.rpartition(":")
        rows.append(take_row(out, take, stages.split(",")))
    tsv = "\t".join(COLUMNS) + "\n"
    tsv += "".join("\t".join(r[c].replace("\t", " ") for c in COLUMNS) + "\n" for r in rows)
    md = "| " + " | ".join(COLUMNS) + " |\n|" + "---|" * len(COLUMNS) + "\n"
    md += "".join("| " + " | ".join(r[c].replace("|", "\\|") for c in COLUMNS) + " |\n"
                  for r in rows)
    os.makedirs(out, exist_ok=True)
    write_atomic(os.path.join(out, "summary.tsv"), tsv)
    write_atomic(os.path.join(out, "summary.md"), md)
    failed = [r for r in rows if r["status"] != "ok"]
    if report:
        for r in failed:
            print(f"arco workflow: take {r['take']} {r['status']} at stage {r['stage']}"
                  + (f": {r['message']}" if r["message"] else ""), file=sys.stderr)
        print(f"arco workflow: {len(rows) - len(failed)} of {len(rows)} takes done; "
              f"table in {os.path.join(out, 'summary.md')}", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
