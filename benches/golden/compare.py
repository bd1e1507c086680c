#!/usr/bin/env python3
"""Compare two folders written by benches/golden/run.sh: every file byte for byte, except
that JSON is compared as data without its timings (keys ending in _ms, elapsed, wall) and
output paths, and stdout/stderr without the folders' own paths and the binary's name.
Prints each differing file and `files N differ D`; exits 1 when D > 0."""
import json
import os
import re
import sys


def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not re.search(r"(_ms$|elapsed|wall|^output$)", k)}
    if isinstance(o, list):
        return [strip(x) for x in o]
    return o


def main(a, b):
    differ = 0
    names = sorted(set(os.listdir(a)) | set(os.listdir(b)))
    for n in names:
        pa, pb = os.path.join(a, n), os.path.join(b, n)
        if not (os.path.exists(pa) and os.path.exists(pb)):
            print("MISSING", n)
            differ += 1
            continue
        da, db = open(pa, "rb").read(), open(pb, "rb").read()
        if n.endswith(".json"):
            try:
                da, db = strip(json.loads(da)), strip(json.loads(db))
            except ValueError:
                pass
        if n.endswith((".stdout", ".stderr")):
            da = da.replace(os.path.abspath(a).encode(), b"OUT")
            db = db.replace(os.path.abspath(b).encode(), b"OUT")
            da = re.sub(rb"polepatch-[0-9a-f]+ ", b"polepatch ", da)
            db = re.sub(rb"polepatch-[0-9a-f]+ ", b"polepatch ", db)
        if da != db:
            print("DIFF", n)
            differ += 1
    print("files", len(names), "differ", differ)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
