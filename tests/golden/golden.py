#!/usr/bin/env python3
"""Golden outputs of `grip solve`: a change that should leave results alone must leave them
byte-identical.

For each case of CASES this runs `grip solve SCENE --out R --events E --threads 1` and compares
the result JSON and the event NDJSON byte for byte with tests/golden/NAME.result.json.gz and
NAME.events.ndjson.gz, after two edits of both texts and nothing else:
  - wall times are set to 0: the values of the members "seconds" (summary, steps,
    step_finished) and "elapsed_ms" (iteration events), the only timings the outputs carry;
  - every "failure" member (an object) is removed with its comma;
  - members new since the files were stored, removed the same way: "checks" (an object: each
    step's step checks, issue 33.1) and the effective scene's "outside_candidates" (issue 33.3).
The stored files are those edited texts, gzip-compressed (mtime 0, so they are reproducible).

  golden.py GRIP_BINARY check     the test (exit 1 on a difference, naming its first byte)
  golden.py GRIP_BINARY record    rewrite the stored files (only for a change meant to alter
                                  results; say which in the commit)
"""
import gzip
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "schemas", "examples")

# name -> scene; each solves in under half a second (one thread, so that the sums' order and
# with it every digit is the same from run to run). Friction: sliding-block,
# block-held-by-friction (held by contact only); a failing run: friction-limit (the held block
# sheared beyond what friction holds).
CASES = {
    "hertz": os.path.join(EXAMPLES, "hertz.json"),
    "sliding-block": os.path.join(EXAMPLES, "sliding-block.json"),
    "block-held-by-friction": os.path.join(EXAMPLES, "block-held-by-friction.json"),
    "beam-on-cylinder": os.path.join(EXAMPLES, "beam-on-cylinder.json"),
    "friction-limit": os.path.join(HERE, "friction-limit.json"),
}

TIMING = re.compile(rb'"(seconds|elapsed_ms)":(-?[0-9][0-9.eE+-]*)')


def drop_failures(text: bytes, key: bytes = b'"failure":{') -> bytes:
    """Removes every `"failure":{...}` member (or another object member) and the comma that joined it."""
    out = bytearray()
    i = 0
    while True:
        k = text.find(key, i)
        if k < 0:
            out += text[i:]
            return bytes(out)
        j = k + len(key)
        depth, in_string = 1, False
        while depth:
            c = text[j]
            if in_string:
                if c == ord("\\"):
                    j += 1
                elif c == ord('"'):
                    in_string = False
            elif c == ord('"'):
                in_string = True
            elif c == ord("{"):
                depth += 1
            elif c == ord("}"):
                depth -= 1
            j += 1
        before = text[i:k]
        if before.endswith(b","):
            out += before[:-1]  # ,"failure":{...}
        else:
            out += before
            if text[j:j + 1] == b",":
                j += 1  # {"failure":{...},
        i = j


# Members added after the stored files: the step checks' record and the scene option.
NEW_STRING_MEMBERS = re.compile(rb',"outside_candidates":"(add|fail)"|"outside_candidates":"(add|fail)",?')


def normalize(text: bytes) -> bytes:
    text = drop_failures(drop_failures(text), b'"checks":{')
    return TIMING.sub(rb'"\1":0', NEW_STRING_MEMBERS.sub(b"", text))


def solve(grip: str, scene: str, folder: str):
    result = os.path.join(folder, "result.json")
    events = os.path.join(folder, "events.ndjson")
    run = subprocess.run([grip, "solve", scene, "--out", result, "--events", events, "--threads", "1"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if run.returncode not in (0, 1):
        raise SystemExit(f"grip solve {scene} exited {run.returncode}: {run.stderr.decode()}")
    with open(result, "rb") as r, open(events, "rb") as e:
        return run.returncode, normalize(r.read()), normalize(e.read())


def first_difference(a: bytes, b: bytes) -> str:
    n = next((i for i in range(min(len(a), len(b))) if a[i] != b[i]), min(len(a), len(b)))
    return (f"first difference at byte {n} (lengths {len(a)} / {len(b)}):\n"
            f"  stored: {a[max(0, n - 80):n + 80]!r}\n  now:    {b[max(0, n - 80):n + 80]!r}")


def main() -> int:
    grip, mode = sys.argv[1], sys.argv[2]
    failed = 0
    for name, scene in CASES.items():
        with tempfile.TemporaryDirectory() as folder:
            code, result, events = solve(grip, scene, folder)
        for suffix, text in ((".result.json.gz", result), (".events.ndjson.gz", events)):
            path = os.path.join(HERE, name + suffix)
            if mode == "record":
                with open(path, "wb") as f:
                    f.write(gzip.compress(text, mtime=0))
                print(f"recorded {name}{suffix} (exit {code}, {len(text)} bytes)")
                continue
            with open(path, "rb") as f:
                stored = gzip.decompress(f.read())
            if stored == text:
                print(f"{name}{suffix}: identical ({len(text)} bytes)")
            else:
                failed += 1
                print(f"{name}{suffix}: DIFFERS; {first_difference(stored, text)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
