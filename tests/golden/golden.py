#!/usr/bin/env python3
"""Golden outputs of `grip solve`: a change that should leave results alone must leave every
number of them alone to 1e-12 relative (a change of the order of floating-point sums, as in a
rewritten element kernel, may move the last bits and nothing more).

For each case of CASES this runs `grip solve SCENE --out R --events E --threads 1` and compares
the result JSON and the event NDJSON with tests/golden/NAME.result.json.gz and
NAME.events.ndjson.gz, member by member (compare): strings, booleans, integers and the
structure exactly; a number written with a fraction or exponent within 1e-12 of its own size,
or of the largest size the same member takes in the stored document (a displacement near the
clamp beside the tip's), or within one unit of its last written digit where the result rounds
it to fewer digits than a double holds (a stress written as -3660.372); a contact error (an
object with a displacement_scale: penetration, v2, bound) within 1e-12 of that scale. A member
the stored document lacks is new output and passes (it cannot alter an existing result).
Not compared: the members of PATH, which record how the solver got to its answer where
round-off decides it, not the answer: the relative residual Newton stopped at and whether that
was the round-off floor, and the inner loop's iterations, halvings and errors on its way (an
iteration record's v2, v_inf). A sum taken in another order moves them (the slender strip: its
inner loop takes 148 iterations at step 13, or 149) while every displacement stays the same to
1e-13; the real solves, Newton iterations and passes that a change of the tangent would alter
are compared exactly. Element and node fields are written to kFieldDigits = 7 digits
(solver/io/result.hpp): for them the test is as tight as the result. Before the comparison
both texts get two edits and nothing else:
  - wall times are set to 0: the values of the members "seconds" (summary, steps,
    step_finished) and "elapsed_ms" (iteration events), the only timings the outputs carry;
  - every "failure" member (an object) is removed with its comma;
  - members new since the files were stored, removed the same way: "checks" (an object: each
    step's step checks, issue 33.1) and the effective scene's "outside_candidates" (issue 33.3).
The stored files are those edited texts, gzip-compressed (mtime 0, so they are reproducible).

  golden.py GRIP_BINARY check           the test (exit 1 on a difference, naming the first)
  golden.py GRIP_BINARY record [NAME..]  rewrite the stored files (all, or the cases named:
                                         a new case, or a change meant to alter results; say
                                         which in the commit)
"""
import gzip
import json
import math
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "schemas", "examples")

# name -> scene; each solves in under a second (one thread, so that the sums' order and with it
# every digit is the same from run to run). Friction: sliding-block, block-held-by-friction
# (held by contact only); a failing run: friction-limit (the held block sheared beyond what
# friction holds). The continuum's element kinds and laws (issue 39's kernels): q9 finite strain
# (strip-on-cylinder, SVK, slender), q4 (hertz, block-on-foundation: two linear bodies), t6 from
# gmsh (hertz-t6), t3 finite in a pair of bodies (two-cylinders-finite-t3), plasticity at small
# and finite strain (hertz-j2-bbar, hertz-j2-finite), axisymmetric q8 and finite q9
# (hertz-sphere, hertz-sphere-finite); the geometrically exact beam (strip-on-drum-beam, the
# elastica strip-cantilever); mixed u-p rubber (seal-o-ring); partial slip (cattaneo-mindlin);
# the membranes (sheet-stretching, the axisymmetric bulge and punch stretching); two linear
# bodies (two-cylinders); an axisymmetric flat punch. Not here, slower than a second: the gear
# pair (2-6 s) and the press-fit (19 s).
CASES = {
    "hertz": os.path.join(EXAMPLES, "hertz.json"),
    "sliding-block": os.path.join(EXAMPLES, "sliding-block.json"),
    "block-held-by-friction": os.path.join(EXAMPLES, "block-held-by-friction.json"),
    "beam-on-cylinder": os.path.join(EXAMPLES, "beam-on-cylinder.json"),
    "friction-limit": os.path.join(HERE, "friction-limit.json"),
    "strip-on-cylinder": os.path.join(EXAMPLES, "strip-on-cylinder.json"),
    "block-on-foundation": os.path.join(EXAMPLES, "block-on-foundation.json"),
    "hertz-t6": os.path.join(EXAMPLES, "hertz-t6.json"),
    "hertz-sphere": os.path.join(EXAMPLES, "hertz-sphere.json"),
    "two-cylinders-finite-t3": os.path.join(HERE, "two-cylinders-finite-t3.json"),
    "hertz-j2-bbar": os.path.join(HERE, "hertz-j2-bbar.json"),
    "hertz-j2-finite": os.path.join(HERE, "hertz-j2-finite.json"),
    "hertz-sphere-finite": os.path.join(HERE, "hertz-sphere-finite.json"),
    "strip-on-drum-beam": os.path.join(EXAMPLES, "strip-on-drum-beam.json"),
    "strip-cantilever": os.path.join(EXAMPLES, "strip-cantilever.json"),
    "seal-o-ring": os.path.join(EXAMPLES, "seal-o-ring.json"),
    "cattaneo-mindlin": os.path.join(EXAMPLES, "cattaneo-mindlin.json"),
    "sheet-stretching": os.path.join(EXAMPLES, "sheet-stretching.json"),
    "two-cylinders": os.path.join(EXAMPLES, "two-cylinders.json"),
    "flat-punch-axisymmetric": os.path.join(EXAMPLES, "flat-punch-axisymmetric.json"),
    "hydraulic-bulge-axisymmetric": os.path.join(EXAMPLES, "hydraulic-bulge-axisymmetric.json"),
    "punch-stretching-axisymmetric": os.path.join(EXAMPLES, "punch-stretching-axisymmetric.json"),
}

RELATIVE = 1e-12
PATH = {"relative_residual", "at_round_off_floor", "inner_iterations", "halvings"}
ITERATION_ERRORS = {"v2", "v_inf"}  # in an iteration record (one with "halvings")

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


class Real(float):
    """A number written with a fraction or exponent, with its text (its last written digit)."""

    def __new__(cls, text: str):
        r = super().__new__(cls, float(text))
        r.text = text
        return r


def parse(text: bytes):
    return json.loads(text, parse_float=Real)


def last_digit_unit(text: str) -> float:
    """The value of one unit in the last written digit of a decimal number's text, or 0 where
    it carries 15 significant digits or more (a double written in full)."""
    mantissa, _, exponent = text.lower().partition("e")
    digits = mantissa.lstrip("-").replace(".", "").lstrip("0")
    if len(digits) >= 15:
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def member_scales(doc, scales=None, key=""):
    """The largest |value| of each member name over the document (array items keep their member's)."""
    scales = {} if scales is None else scales
    if isinstance(doc, dict):
        for k, v in doc.items():
            member_scales(v, scales, k)
    elif isinstance(doc, list):
        for v in doc:
            member_scales(v, scales, key)
    elif isinstance(doc, Real) and math.isfinite(doc):
        scales[key] = max(scales.get(key, 0.0), abs(doc))
    return scales


def first_difference(stored, now, scales, path="", key="", floor=0.0):
    """The path and values of the first difference beyond the tolerances, or None."""
    if isinstance(stored, dict):
        if not isinstance(now, dict):
            return f"{path}: stored an object, now {now!r:.80}"
        iteration = "halvings" in stored
        for k, v in stored.items():
            if k in PATH or (iteration and k in ITERATION_ERRORS):
                continue
            if k not in now:
                return f"{path}/{k}: missing now"
            d = first_difference(v, now[k], scales, f"{path}/{k}", k, abs(stored.get("displacement_scale", 0.0)))
            if d:
                return d
        return None
    if isinstance(stored, list):
        if not isinstance(now, list) or len(now) != len(stored):
            return f"{path}: stored {len(stored)} items, now {len(now) if isinstance(now, list) else now!r:.80}"
        for i, (a, b) in enumerate(zip(stored, now)):
            d = first_difference(a, b, scales, f"{path}/{i}", key)
            if d:
                return d
        return None
    if isinstance(stored, Real) and isinstance(now, (int, float)) and not isinstance(now, bool):
        a, b = float(stored), float(now)
        if a == b or abs(a - b) <= RELATIVE * max(abs(a), abs(b), scales.get(key, 0.0), floor):
            return None
        if abs(a - b) <= 1.0001 * max(last_digit_unit(stored.text), last_digit_unit(getattr(now, "text", ""))):
            return None
        return f"{path}: stored {stored.text}, now {getattr(now, 'text', now)} (relative {abs(a - b) / max(abs(a), abs(b)):.2e})"
    if type(stored) is not type(now) or stored != now:
        return f"{path}: stored {stored!r:.80}, now {now!r:.80}"
    return None


def compare(stored: bytes, now: bytes, ndjson: bool) -> str:
    """None where the documents agree (see the module's note), else the first difference."""
    if stored == now:
        return None
    if ndjson:
        a, b = stored.splitlines(), now.splitlines()
        if len(a) != len(b):
            return f"stored {len(a)} events, now {len(b)}"
        docs_a, docs_b = [parse(x) for x in a], [parse(x) for x in b]
    else:
        docs_a, docs_b = [parse(stored)], [parse(now)]
    scales = {}
    for d in docs_a:
        member_scales(d, scales)
    for i, (x, y) in enumerate(zip(docs_a, docs_b)):
        d = first_difference(x, y, scales, f"[{i}]" if ndjson else "")
        if d:
            return d
    return None


def main() -> int:
    grip, mode, names = sys.argv[1], sys.argv[2], sys.argv[3:]
    failed = 0
    for name, scene in CASES.items():
        if names and name not in names:
            continue
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
            difference = compare(stored, text, suffix.startswith(".events"))
            if difference is None:
                print(f"{name}{suffix}: {'identical' if stored == text else 'the same to 1e-12'} ({len(text)} bytes)")
            else:
                failed += 1
                print(f"{name}{suffix}: DIFFERS at {difference}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
