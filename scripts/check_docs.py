#!/usr/bin/env python3
"""Checks that docs/*.md cannot rot: every relative link resolves to a file or folder of the
repository (and its #anchor to a heading of the linked page), and every repository path that
the pages cite (solver/..., tests/..., schemas/..., in links or in the text) exists. With
--no-outside-references, also that no tracked file cites the team's notes outside the
repository. Standard library only; run with /usr/bin/python3 (the ctest docs_links).

    /usr/bin/python3 scripts/check_docs.py                           # docs/*.md (ctest docs_links)
    /usr/bin/python3 scripts/check_docs.py --no-outside-references   # and every tracked file
    /usr/bin/python3 scripts/check_docs.py --outside-references-only # (ctest docs_no_outside_references)
"""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"

LINK = re.compile(r"(?<!\!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
# A path that starts at one of the repository's top folders.
TOP = r"(?:solver|server|apps|tests|schemas|scripts|bench|clients|deploy|docs)"
PATH = re.compile(r"(?<![\w./-])" + TOP + r"/[\w./-]*")
FENCE = re.compile(r"^(```|~~~)")
# The notes these pages replace, spelled so that this file does not cite them itself.
OUTSIDE = ["ALGORITHM" + ".md", "DESIGN" + ".md", ".." + "/shared"]


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip().lower())
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(page):
    found, seen = set(), {}
    in_fence = False
    for line in page.read_text().splitlines():
        if FENCE.match(line):
            in_fence = not in_fence
        if in_fence or not line.startswith("#"):
            continue
        base = slug(line.lstrip("#"))
        n = seen.get(base, 0)
        seen[base] = n + 1
        found.add(base if n == 0 else f"{base}-{n}")
    return found


def check_page(page, problems):
    text = page.read_text()
    where = page.relative_to(ROOT)
    for number, line in enumerate(text.splitlines(), 1):
        for match in LINK.finditer(line):
            target = match.group(1) or match.group(2)
            if re.match(r"^[a-z]+:", target):
                continue  # http:, https:, mailto:
            file_part, _, anchor = target.partition("#")
            resolved = (page.parent / file_part).resolve() if file_part else page
            if not resolved.exists():
                problems.append(f"{where}:{number}: link {target}: no such file")
                continue
            if ROOT not in resolved.parents and resolved != ROOT:
                problems.append(f"{where}:{number}: link {target} leaves the repository")
                continue
            if anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
                problems.append(f"{where}:{number}: link {target}: no heading #{anchor} in {resolved.relative_to(ROOT)}")
        for match in PATH.finditer(line):
            path = match.group(0).rstrip(".")
            after = line[match.end():match.end() + 1]
            if after in ("<", "*", "{"):
                continue  # a pattern (solver/io/scene_<model>.cpp), not a path
            if not (ROOT / path).exists():
                problems.append(f"{where}:{number}: cites {path}: no such file or folder")


def outside_references(problems):
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for name in files.decode().split("\0"):
        path = ROOT / name
        if not name or not path.is_file():
            continue
        try:
            text = path.read_text()
        except (UnicodeDecodeError, OSError):
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for word in OUTSIDE:
                if word in line:
                    problems.append(f"{name}:{number}: cites {word}, which is not in the repository: cite docs/")


def main():
    problems = []
    args = sys.argv[1:]
    pages = sorted(DOCS.glob("*.md"))
    if "--outside-references-only" not in args:
        if not pages:
            problems.append("docs/ has no pages")
        for page in pages:
            check_page(page, problems)
    if "--no-outside-references" in args or "--outside-references-only" in args:
        outside_references(problems)
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        return 1
    if "--outside-references-only" in args:
        print("no tracked file cites the notes outside the repository")
    else:
        print(f"{len(pages)} pages of docs/: every link and cited path resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
