#!/usr/bin/env python3
"""Lists C++ function bodies longer than a limit (default 150 lines), outside tests/.

A body is a top-level or namespace-level brace block whose opening line closes a parameter list (`) {`, `) const {`,
`) -> T {`, ...); lambdas count towards the function that holds them. Usage: tools/function_lengths.py [--limit N]
[ROOT]. Exit 1 when any body is longer than the limit.
"""
import argparse
import pathlib
import re
import sys

HEADER = re.compile(r"\)\s*(const\s*)?(noexcept\s*)?(override\s*)?(->\s*[\w:<>,\s*&]+)?\s*\{\s*(//.*)?$")
SKIP_DIRS = {"tests", "build", ".git", "examples"}


def strip(line):
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])*'", "''", line)
    return line.split("//")[0]


def bodies(path):
    lines = path.read_text(errors="replace").splitlines()
    depth, start, name, in_comment = 0, None, None, False
    for i, raw in enumerate(lines, 1):
        line = raw
        if in_comment:
            if "*/" not in line:
                continue
            line, in_comment = line.split("*/", 1)[1], False
        if "/*" in line and "*/" not in line.split("/*", 1)[1]:
            line, in_comment = line.split("/*", 1)[0], True
        code = strip(line)
        if re.match(r"\s*(inline\s+)?namespace\b[^;]*\{", code) or re.match(r"\s*\}\s*$", code) and "namespace" in raw:
            continue
        if start is None and depth == 0 and HEADER.search(raw):
            head = i
            while head > 1 and lines[head - 1][:1] in (" ", "\t", ")"):
                head -= 1
            start, name, base = i, lines[head - 1].strip(), depth
        depth += code.count("{") - code.count("}")
        if start is not None and depth <= base:
            yield name, start, i - start + 1
            start = None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=150)
    parser.add_argument("root", nargs="?", default=".")
    args = parser.parse_args()
    long_ones = []
    for path in sorted(pathlib.Path(args.root).rglob("*")):
        if path.suffix not in (".cc", ".h") or SKIP_DIRS & set(path.relative_to(args.root).parts):
            continue
        for name, start, length in bodies(path):
            if length > args.limit:
                long_ones.append((length, f"{path}:{start}", name))
    for length, where, name in sorted(long_ones, reverse=True):
        print(f"{length:5d}  {where}  {name[:90]}")
    print(f"{len(long_ones)} function(s) over {args.limit} lines")
    return 1 if long_ones else 0


if __name__ == "__main__":
    sys.exit(main())
