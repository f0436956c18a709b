#!/usr/bin/env python3
"""Functions and files longer than the code's limits (issue #32): a function
over LIMIT_FUNCTION lines or a file over LIMIT_FILE lines must say why it
cannot be split, in a comment containing "cannot be split" within the ten
lines above it (for a file: in its first 30 lines).

    scripts/long_functions.py [ROOT] [--list N]

exits 1 naming each one that does not; --list N prints the N longest
functions whatever their length. Counting is by braces at namespace level,
after removing comments, strings and character literals: every function
defined at namespace level, from its signature's first line to its closing
brace, and every member function defined inside a class, struct or union
body the same way (the class itself is not a function; tables initialised
with `= {` are data, not functions).
"""
import os
import re
import sys

LIMIT_FUNCTION = 150
LIMIT_FILE = 1000
FOLDERS = ("src", "include", "apps", "python/src")
STRIP = re.compile(r'//[^\n]*|/\*.*?\*/|R"([^(]*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'',
                   re.S)


def blank(match):
    return "".join("\n" if c == "\n" else " " for c in match.group(0))


def bodies(text):
    """(first line, last line, signature) of each top-level body."""
    code = STRIP.sub(blank, text)
    lines = code.split("\n")
    found, depth, namespaces, start = [], 0, [], None
    statement_start = 0
    for number, line in enumerate(lines):
        for column, char in enumerate(line):
            if char == "{":
                head = " ".join(lines[statement_start:number + 1])
                statement = " ".join(lines[statement_start:number] + [line[:column]]).strip()
                scope = depth == len(namespaces) and (
                    (re.search(r"\b(namespace|extern\s*$)", head[-200:])
                     and not re.search(r"\)\s*(const\s*)?(noexcept\s*)?(->[^{]*)?\{?\s*$", head))
                    # A class's body: its member functions are measured
                    # one by one, as functions at namespace level are.
                    or re.match(r"(template\s*<.*>\s*)?(class|struct|union)\s+[\w:]+"
                                r"(\s+final)?(\s*:[^(){}]*)?$", statement))
                if scope:
                    namespaces.append(depth)
                    depth += 1
                    statement_start = number + 1
                    continue
                if depth == len(namespaces):
                    start = statement_start
                depth += 1
            elif char == "}":
                depth -= 1
                if namespaces and depth == namespaces[-1]:
                    namespaces.pop()
                    statement_start = number + 1
                elif depth == len(namespaces) and start is not None:
                    head = " ".join(" ".join(lines[start:number + 1]).split())
                    signature = head[:head.index("{")] if "{" in head else head
                    # Class bodies count by their member functions' own
                    # lengths, tables (`= {`) are data: neither is a function.
                    if "(" in signature and not re.search(r"=\s*$", signature) and not re.match(
                            r"(template\s*<[^>]*>\s*)?(class|struct|union|enum)\b", signature):
                        found.append((start, number, " ".join(lines[start].split())[:90]))
                    start = None
                    statement_start = number + 1
            elif char == ";" and depth == len(namespaces):
                statement_start = number + 1
        if depth == len(namespaces) and (not line.strip() or re.match(
                r"\s*(public|private|protected)\s*:\s*$", line)):
            statement_start = number + 1
    return found


def justified(raw_lines, first):
    window = "\n".join(raw_lines[max(0, first - 10):first + 1])
    return "cannot be split" in window


def main():
    args = [a for a in sys.argv[1:]]
    list_count = 0
    if "--list" in args:
        i = args.index("--list")
        list_count = int(args[i + 1])
        del args[i:i + 2]
    root = args[0] if args else os.path.join(os.path.dirname(__file__), "..")
    problems, everything = [], []
    for folder in FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for name in sorted(files):
                if not name.endswith((".cpp", ".hpp")):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                text = open(path, encoding="utf-8").read()
                raw = text.split("\n")
                if len(raw) > LIMIT_FILE and "cannot be split" not in "\n".join(raw[:30]):
                    problems.append(f"{rel}: {len(raw)} lines (limit {LIMIT_FILE})")
                for first, last, signature in bodies(text):
                    length = last - first + 1
                    everything.append((length, rel, first + 1, signature))
                    if length > LIMIT_FUNCTION and not justified(raw, first):
                        problems.append(f"{rel}:{first + 1}: {length} lines (limit {LIMIT_FUNCTION}): "
                                        f"{signature}")
    for length, rel, line, signature in sorted(everything, reverse=True)[:list_count]:
        print(f"{length:5d} {rel}:{line}: {signature}")
    for problem in problems:
        print(problem)
    if problems:
        print(f"long_functions: {len(problems)} function(s) or file(s) over the limits without a reason")
        return 1
    print("long_functions: every function and file within the limits or justified")
    return 0


if __name__ == "__main__":
    sys.exit(main())
