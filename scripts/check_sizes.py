#!/usr/bin/env python3
"""The size limits of issue 40: no non-test source file over 800 lines and no function over
120 lines.

Usage: python3 scripts/check_sizes.py [--files N] [--fns N] [ROOT]

Walks ROOT/crates/*/src (default ROOT: the repository holding this script), leaves out
`#[cfg(test)]` items (the test modules kept inside a source file) and files named `tests.rs`
or `*_tests.rs` that only a `#[cfg(test)] mod` declares, and counts physical lines. A function
is `fn NAME ... { ... }`; its length runs from the line of `fn` to the line of its closing
brace. Braces inside comments, strings, raw strings and char literals do not count. The
page's scripts (`.js` under crates/*/src) and the Python package (`.py` under crates/*/python)
are held to the file limit too, and Python's functions (by its own parser) to the function
limit. Prints every file and function over its limit and exits 1 if there is any, 0 otherwise.
"""

import ast

import argparse
import os
import re
import sys


def blank_non_code(text):
    """Returns text with comments, string and char literals replaced by spaces (newlines kept),
    so that braces and keywords found afterwards are code."""
    out = []
    i, n = 0, len(text)

    def keep_newlines(s):
        return "".join("\n" if c == "\n" else " " for c in s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(keep_newlines(text[i:j]))
            i = j
        elif re.match(r'b?r#*"', text[i:i + 130]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'b?r(#*)"', text[i:])
            close = '"' + m.group(1)
            j = text.find(close, i + m.end())
            j = n if j < 0 else j + len(close)
            out.append(keep_newlines(text[i:j]))
            i = j
        elif c == '"' or (c == "b" and text.startswith('b"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_"))):
            j = i + (2 if c == "b" else 1)
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(keep_newlines(text[i:j + 1]))
            i = j + 1
        elif c == "'":
            # A char literal ('x', '\n', '\u{..}', '{') or a lifetime ('a); only the former is blanked.
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\x[0-9a-fA-F]{2}|\\.|[^\\'])'", text[i:i + 12])
            if m:
                out.append(" " * m.end())
                i += m.end()
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching_brace(code, open_at):
    depth = 0
    for j in range(open_at, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


def item_end(code, start):
    """End offset of the item starting at `start`: its brace block, or its `;`."""
    for j in range(start, len(code)):
        if code[j] == ";":
            return j
        if code[j] == "{":
            return matching_brace(code, j)
    return len(code) - 1


CFG_TEST = re.compile(r"#\[cfg\(test\)\]")
FN = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)")


def line_of(code, offset):
    return code.count("\n", 0, offset) + 1


def measure(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    code = blank_non_code(text)
    test_lines = set()
    for m in CFG_TEST.finditer(code):
        end = item_end(code, m.end())
        test_lines.update(range(line_of(code, m.start()), line_of(code, end) + 1))
    total = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
    lines = total - len(test_lines)
    fns = []
    for m in FN.finditer(code):
        first = line_of(code, m.start())
        if first in test_lines:
            continue
        # The body's brace: the first `{` before any `;` (a `;` first means a declaration).
        j = m.end()
        while j < len(code) and code[j] not in "{;":
            j += 1
        if j >= len(code) or code[j] == ";":
            continue
        last = line_of(code, matching_brace(code, j))
        fns.append((m.group(1), first, last - first + 1))
    return lines, fns


def test_only_files(root):
    """Files declared only as `#[cfg(test)] mod NAME;`: they are test modules kept in files."""
    found = set()
    for dirpath, _, names in os.walk(root):
        for name in names:
            if not name.endswith(".rs"):
                continue
            path = os.path.join(dirpath, name)
            with open(path, encoding="utf-8") as f:
                code = blank_non_code(f.read())
            for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", code):
                base = os.path.dirname(path)
                stem = os.path.splitext(name)[0]
                for cand in (os.path.join(base, m.group(1) + ".rs"),
                             os.path.join(base, stem, m.group(1) + ".rs"),
                             os.path.join(base, m.group(1), "mod.rs")):
                    found.add(os.path.normpath(cand))
    return found


def other_sources(args):
    """The page's scripts and the Python package: files over the line limit, and Python
    functions over the function limit; returns how many, having printed each."""
    over = 0
    crates = os.path.join(args.root, "crates")
    for crate in sorted(os.listdir(crates)):
        for sub, ext in (("src", ".js"), ("python", ".py")):
            top = os.path.join(crates, crate, sub)
            for dirpath, _, names in sorted(os.walk(top)):
                for name in sorted(n for n in names if n.endswith(ext)):
                    path = os.path.join(dirpath, name)
                    rel = os.path.relpath(path, args.root)
                    with open(path, encoding="utf-8") as f:
                        text = f.read()
                    lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
                    if lines > args.files:
                        print(f"{rel}: {lines} lines (limit {args.files})")
                        over += 1
                    if ext == ".py":
                        for node in ast.walk(ast.parse(text, filename=path)):
                            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                                length = node.end_lineno - node.lineno + 1
                                if length > args.fns:
                                    print(f"{rel}:{node.lineno}: def {node.name} is {length} lines (limit {args.fns})")
                                    over += 1
    return over


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("root", nargs="?", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    ap.add_argument("--files", type=int, default=800, help="most lines a source file may have (default 800)")
    ap.add_argument("--fns", type=int, default=120, help="most lines a function may have (default 120)")
    args = ap.parse_args()
    crates = os.path.join(args.root, "crates")
    over = 0
    for crate in sorted(os.listdir(crates)):
        src = os.path.join(crates, crate, "src")
        if not os.path.isdir(src):
            continue
        skip = test_only_files(src)
        for dirpath, _, names in sorted(os.walk(src)):
            for name in sorted(names):
                path = os.path.normpath(os.path.join(dirpath, name))
                if not name.endswith(".rs") or path in skip:
                    continue
                lines, fns = measure(path)
                rel = os.path.relpath(path, args.root)
                if lines > args.files:
                    print(f"{rel}: {lines} lines outside #[cfg(test)] (limit {args.files})")
                    over += 1
                for fn, first, length in fns:
                    if length > args.fns:
                        print(f"{rel}:{first}: fn {fn} is {length} lines (limit {args.fns})")
                        over += 1
    over += other_sources(args)
    if over:
        print(f"{over} over the limits", file=sys.stderr)
        return 1
    print(f"every source file within {args.files} lines and every function within {args.fns}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
