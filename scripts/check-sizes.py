#!/usr/bin/env python3
"""Checks the code base's size rules (CONTRIBUTING.md): no source file in src/ or bench/ over 600
lines, no function in src/, apps/, bench/ or python/src/ over 80 lines (signature to closing
brace) unless the comment right above it says why (a line starting `// Long:`). Prints each breach
as FILE:LINE and exits 1.

Usage: scripts/check-sizes.py [ROOT] [--list N]   (--list N: the N longest functions, no check)
"""
import pathlib
import re
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 80
# The folders walked (the function limit holds in each), and those the file limit holds in too.
PARTS = ("src", "apps", "bench", "python/src")
FILE_LIMIT_PARTS = ("src", "bench")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try|return|namespace|struct|class|"
                     r"enum|union|extern)\b")
# A function definition's head: a name, its parameters, qualifiers, then the opening brace.
HEAD = re.compile(r"[\w:~<>\]]+\s*\((?:[^()]|\([^()]*\))*\)\s*(?:const\s*)?(?:noexcept\s*)?"
                  r"(?:override\s*)?(?:->\s*[\w:<>,\s\*&]+)?(?::\s*[^{]*)?\{\s*$")


def strip(line):
    """The line without comments and string/char literals (enough for brace counting)."""
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])'", "''", line)
    return line.split("//")[0]


def functions(lines):
    """(first line, last line, head) of each function body, 1-based."""
    found, statement, start = [], "", None
    i = 0
    while i < len(lines):
        code = strip(lines[i])
        if not statement.strip():
            start = i
        statement += " " + code.strip()
        if code.rstrip().endswith("{") and HEAD.search(statement.strip()) and \
                not CONTROL.match(statement) and "=" not in statement.split("(")[0] and \
                "[" not in statement.split("(")[0]:
            depth, k = 0, i
            while k < len(lines):
                c = strip(lines[k])
                depth += c.count("{") - c.count("}")
                if depth <= 0 and k > i or (depth == 0 and k == i):
                    break
                k += 1
            found.append((start + 1, k + 1, statement.strip()))
            statement = ""
            i += 1
            continue
        if code.rstrip().endswith((";", "{", "}")) or code.strip().startswith("#") or \
                not code.strip():
            statement = ""
        i += 1
    return found


def justified(lines, first):
    k = first - 2
    while k >= 0 and lines[k].lstrip().startswith("//"):
        if lines[k].lstrip().startswith("// Long:"):
            return True
        k -= 1
    return False


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = pathlib.Path(args[0] if args else pathlib.Path(__file__).resolve().parent.parent)
    listing = int(argv[argv.index("--list") + 1]) if "--list" in argv else 0
    if listing:
        args = args[:1] if args and not args[0].isdigit() else []
        root = pathlib.Path(args[0]) if args else pathlib.Path(__file__).resolve().parent.parent
    breaches, lengths = [], []
    for part in PARTS:
        for path in sorted((root / part).rglob("*")):
            if path.suffix not in (".cpp", ".hpp"):
                continue
            lines = path.read_text().split("\n")
            rel = path.relative_to(root)
            if part in FILE_LIMIT_PARTS and len(lines) - 1 > MAX_FILE_LINES:
                breaches.append(f"{rel}: {len(lines) - 1} lines (at most {MAX_FILE_LINES})")
            for first, last, head in functions(lines):
                n = last - first + 1
                lengths.append((n, f"{rel}:{first}", head[:60]))
                if n > MAX_FUNCTION_LINES and not justified(lines, first):
                    breaches.append(f"{rel}:{first}: function of {n} lines (at most "
                                    f"{MAX_FUNCTION_LINES}, or a `// Long:` comment saying why): "
                                    f"{head[:60]}")
    if listing:
        for n, where, head in sorted(lengths, reverse=True)[:listing]:
            print(f"{n:4d} {where} {head}")
        return 0
    for b in breaches:
        print(b)
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
