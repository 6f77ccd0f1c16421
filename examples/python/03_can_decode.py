#!/usr/bin/env python3
"""03 — decode a CAN log with a DBC and plot the signals.

Reads a bus log recorded by another tool (a Vector ASC file from python-can's test data) and
a DBC (socialledge.dbc from cantools' tests), both in the shared CAN corpus; decodes every
frame whose id the DBC knows with lash.can.Database.decode and plots each decoded signal
over time (in the unit the DBC gives it).

If this lash cannot read the log's format itself, the frames are read by python-can and the
can.Message objects are handed to decode() as they are: lash accepts them wherever a frame is.

    python3 examples/python/03_can_decode.py [--dbc FILE] [--log FILE] [--out 03_can_decode.png]
"""
import argparse
import collections
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import lash  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "..", "..", "..", "shared", "data", "can-corpus")


def frames_of(path):
    """(timestamp [s], id, extended, payload) of every data frame of a log."""
    try:
        rows = lash.can.read_log(path)
        print("read %d frames with lash.can.read_log" % len(rows))
        for r in rows:
            flags = int(r["flags"])
            if flags & lash.can.FLAG_REMOTE:
                continue
            yield float(r["timestamp"]), int(r["id"]), bool(flags & lash.can.FLAG_EXTENDED), bytes(r["data"][:int(r["dlc"])])
    except lash.InputError as e:
        import can  # python-can reads it instead; its Message objects go to decode() unchanged
        print("lash cannot read this log (%s); reading it with python-can" % e.message)
        with can.LogReader(path) as reader:
            for m in reader:
                if not (m.is_remote_frame or m.is_error_frame):
                    yield m.timestamp, m.arbitration_id, m.is_extended_id, m


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dbc", default=os.path.join(CORPUS, "dbc", "socialledge.dbc"))
    ap.add_argument("--log", default=os.path.join(CORPUS, "logs", "vector-asc", "issue_1256.asc"))
    ap.add_argument("--out", default="03_can_decode.png", help="figure file (PNG)")
    args = ap.parse_args()

    db = lash.can.Database(args.dbc)
    known = {(m["id"], m["extended"]): name for name, m in db.messages.items()}
    series = collections.defaultdict(lambda: ([], []))
    decoded = skipped = 0
    for t, ident, ext, payload in frames_of(args.log):
        name = known.get((ident, ext))
        if name is None:
            skipped += 1
            continue
        try:
            values = db.decode(payload) if not isinstance(payload, bytes) else db.decode(ident, payload, extended=ext)
        except lash.InputError:  # e.g. a frame shorter than the DBC's message
            skipped += 1
            continue
        decoded += 1
        for sig, x in values.items():
            ts, xs = series[(name, sig)]
            ts.append(t)
            xs.append(x)
    print("decoded %d frames, %d not in the DBC or too short; %d signals" % (decoded, skipped, len(series)))

    # the signals that change most often, one panel each
    busiest = sorted(series, key=lambda k: -len(set(series[k][1])))[:6]
    fig, axes = plt.subplots(len(busiest), 1, figsize=(9, 2 * len(busiest) + 1), sharex=True, squeeze=False)
    t0 = min(min(series[k][0]) for k in busiest)
    for ax, key in zip(axes[:, 0], busiest):
        ts, xs = series[key]
        unit = db.messages[key[0]]["signals"][key[1]]["unit"]
        ax.step([x - t0 for x in ts], xs, where="post")
        ax.set_ylabel("%s\n[%s]" % (key[1], unit or "-"), fontsize=8)
        ax.set_title(key[0], fontsize=8, loc="left")
    axes[-1, 0].set_xlabel("t - t0 [s]")
    fig.suptitle("%s decoded with %s" % (os.path.basename(args.log), os.path.basename(args.dbc)))
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print("figure ->", args.out)


if __name__ == "__main__":
    main()
