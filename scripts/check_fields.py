#!/usr/bin/env python3
"""Every request field written once: the field tables of crates/sandslope-request are the only
non-test source that spells a field's flag, its default or its range.

Usage: python3 scripts/check_fields.py [ROOT] [--verbose]

A field is a row `Field::number("k-s", ...)` (or `text`, `switch`, `new`, a robot `quantity`) of a table in
crates/sandslope-request/src; the files holding such rows are the tables. In every other
non-test Rust source file under crates/*/src (test modules, `#[cfg(test)]` items, left out as
scripts/check_sizes.py does) of the front ends (request, cli, serve, py), a field's name must
not appear:

- as a flag `"--k-s"`, or as the word `"k-s"` given to a read, a check or an error (code names
  a field by its row: `K_S.flag`);
- as a clap derive argument named after it (`#[arg(long ...)] pub k_s: ...`), which would
  state its flag, default and help a second time;
- in a default read by name (`number_or("to", 30.0)`, `text_or("robot", ...)`).

The explorer page's inputs (crates/sandslope-serve/src/page/index.html) for a field write no
start or range of their own: the server writes `value`, `min` and `max` from the field's table
when it serves the page, so an input bound to a field (`data-field`, `data-flag`) with one of
them, or an input named after a field and bound to none, is a finding.

The fuzzer (crates/sandslope-fuzz/src) runs the command line and the server as a user does, so
its targets (targets.rs, serve/) spell flags (`"--slope"`) and HTTP fields (`?slope=10&k-n=`):
each must be a field of a table or a flag the CLI declares (a clap `long`), so that a renamed
field cannot leave a fuzz target refused at every input for a reason the fuzzer counts as
handled.

A flag named in any front end's text (a message, a help line: `"give --touchdowns"`) must
be a field of a table or a flag the CLI declares, so a field renamed in its table, or a flag
removed, fails here until every message that names it follows (a planted rename of
`--touchdowns` in a report sentence is caught). Such a mention of a field's flag is a second
spelling all the same (`FIELD.long()` writes it from the row); these are listed as notes,
not failures, with their count.

Files whose requests are not yet read through a table are listed in PENDING with the reason;
they are reported as a note, not a failure, so the list shows the work left. Exits 1 on any
other finding, 0 otherwise.
"""

import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_sizes import CFG_TEST, blank_non_code, item_end, line_of  # noqa: E402

ROW = re.compile(r'(?:Field::(?:number|text|switch|new)|\bquantity)\(\s*"([^"]+)"')
# `#[arg(long, ...)]` then `pub name:`; the attribute may hold lists (`conflicts_with_all = [..]`).
DERIVE = re.compile(
    r"#\[arg\((?:long\b(?!\s*=)(?:[^\[\]]|\[[^\]]*\])*)\)\]\s*(?:///[^\n]*\n\s*)*pub\s+([a-z_][a-z0-9_]*)\s*:"
)
# Where a quoted word names a field: a read, a check or an error naming it.
NAMING = re.compile(
    r'\b(?:text|number|number_or|flag|whole|text_or|required_number|invalid|check_range|check_positive|'
    r'check_range_in|check_positive_in|from_error|Some)\(\s*(?:[A-Za-z_:.]+,\s*)?"([a-z][a-z0-9-]*)"'
)
# The crates of the front ends and their requests: the library and the readers name keys, not fields.
FRONT_ENDS = ("crates/sandslope-request/", "crates/sandslope-cli/", "crates/sandslope-serve/", "crates/sandslope-py/")
DEFAULT_BY_NAME = re.compile(r'\b(?:number_or|text_or)\(\s*"([^"]+)"')

# Requests still reading their fields by name: (path, why). Shrinks as tables are added; empty
# now that every request is read through its table.
PENDING = {}


# A word that is one request's field and, in another file, names something else: (path, word)
# -> what it names there. Not a finding.
OTHER_MEANINGS = {
    ("crates/sandslope-serve/src/http.rs", "body"): "the HTTP request's body, not track's --body",
    ("crates/sandslope-cli/src/commands/sweep.rs", "observed"): "sweep's overlay of measured speeds, not infer's --observed",
    ("crates/sandslope-cli/src/commands/simulate.rs", "observed"): "simulate's overlay of measured speeds on its --slopes figure, not infer's --observed",
    ("crates/sandslope-serve/src/data.rs", "dem"): "the page's /data/dem (the served DEM's heights), not plan's --dem",
}


# The explorer page: its inputs for a field take their start and range from the tables, written
# in by the server when it serves the page (crates/sandslope-serve/src/page.rs).
PAGE = "crates/sandslope-serve/src/page/index.html"
INPUT = re.compile(r"<input\b[^>]*>")
ATTRIBUTE = re.compile(r'\s([a-z][a-z-]*)="([^"]*)"')


def page_findings(root, homes):
    """The page's inputs that write a field's start or range themselves: an input bound to a
    field (`data-field="COMMAND:FLAG"`, a robot quantity's `data-flag`) with a `value`, `min`
    or `max` of its own, and an input named after a field (its id a field's flag) bound to none."""
    path = os.path.join(root, PAGE)
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8") as f:
        text = f.read()
    hits = []
    for m in INPUT.finditer(text):
        attrs = dict(ATTRIBUTE.findall(m.group(0)))
        where = f"{PAGE}:{line_of(text, m.start())}: <input id=\"{attrs.get('id', '')}\">"
        bound = attrs.get("data-field", "").split(":")[-1] or attrs.get("data-flag")
        if bound and bound not in homes:
            hits.append(f"{where} is bound to `{bound}`, which no field table has")
        if not bound and attrs.get("id") in homes:
            hits.append(f"{where} is named after the field `{attrs['id']}` but bound to none (give it data-field)")
        for name in ("value", "min", "max") if bound else ():
            if name in attrs:
                hits.append(
                    f"{where} writes {name}=\"{attrs[name]}\" for the field `{bound}`: the server writes it "
                    "from the field's table (crates/sandslope-serve/src/page.rs)"
                )
    return hits


# The fuzzer's runs of the CLI and the server (its own main.rs has flags of its own).
FUZZ = ("crates/sandslope-fuzz/src/targets.rs", "crates/sandslope-fuzz/src/serve/")
STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"')
FLAG_IN_TEXT = re.compile(r"--([a-z][a-z0-9-]*)")
QUERY_FIELD = re.compile(r"[?&]([a-z][a-z0-9-]*)=")
CLAP_LONG = re.compile(r'\blong\s*=\s*"([a-z][a-z0-9-]*)"|\.long\(\s*"([a-z][a-z0-9-]*)"\s*\)')


def cli_flags(files):
    """Every flag the CLI's clap arguments declare by name: derived (`#[arg(long)] pub k_s`),
    `long = "x"` and `.long("x")`. Flags given as `long = FIELD.flag` are the tables'."""
    flags = set()
    for rel, lines in files.items():
        if not rel.startswith("crates/sandslope-cli/src/"):
            continue
        text = "\n".join(lines)
        flags.update(m.group(1).replace("_", "-") for m in DERIVE.finditer(text))
        flags.update(a or b for a, b in CLAP_LONG.findall(text))
    return flags


def literals(files, prefixes):
    """Every string literal of the files under `prefixes`: (path, line number, literal)."""
    for rel, lines in files.items():
        if rel.startswith(prefixes):
            for n, line in enumerate(lines, 1):
                for lit in STRING.findall(line):
                    yield rel, n, lit


def fuzz_findings(files, homes):
    """The fuzzer's flags and HTTP fields that no table has and the CLI does not declare."""
    known = set(homes) | cli_flags(files)
    hits = []
    for rel, n, lit in literals(files, FUZZ):
        names = FLAG_IN_TEXT.findall(lit) if lit.startswith('"--') else []
        names += QUERY_FIELD.findall(lit) if "/api/" in lit else []
        hits += [f"{rel}:{n}: `{m}` is neither a field of a table nor a flag of the CLI" for m in names if m not in known]
    return hits


def unknown_flag_findings(files, homes):
    """A flag named in a front end's text (a message, a help line) that no table has and the
    CLI does not declare: a field renamed in its table, or a flag removed, leaves the messages
    that name it here (`--emulate-*` names a family, not a flag)."""
    known = set(homes) | cli_flags(files)
    return [
        f"{rel}:{n}: `--{flag}` is neither a field of a table nor a flag of the CLI"
        for rel, n, lit in literals(files, FRONT_ENDS)
        for flag in FLAG_IN_TEXT.findall(lit)
        if flag not in known and not flag.endswith("-")
    ]


def prose_notes(files, homes):
    """A field's flag inside a longer string (a message), outside the field's table."""
    return [
        f"{rel}:{n}: --{flag}"
        for rel, n, lit in literals(files, FRONT_ENDS)
        for flag in FLAG_IN_TEXT.findall(lit)
        if flag in homes and rel not in homes[flag] and lit != f'"--{flag}"'
    ]


def code_outside_tests(path):
    """The file's text with `#[cfg(test)]` items blanked (newlines kept)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    code = blank_non_code(text)
    lines = text.split("\n")
    for m in CFG_TEST.finditer(code):
        end = item_end(code, m.end())
        for n in range(line_of(code, m.start()), line_of(code, end) + 1):
            if n - 1 < len(lines):
                lines[n - 1] = ""
    return lines


def sources(root):
    crates = os.path.join(root, "crates")
    for crate in sorted(os.listdir(crates)):
        src = os.path.join(crates, crate, "src")
        for dirpath, _, names in sorted(os.walk(src)):
            for name in sorted(names):
                if name.endswith(".rs") and name != "tests.rs" and not name.endswith("_tests.rs"):
                    yield os.path.relpath(os.path.join(dirpath, name), root)


def main():
    args = [a for a in sys.argv[1:] if a != "--verbose"]
    root = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    files = {rel: code_outside_tests(os.path.join(root, rel)) for rel in sources(root)}
    homes = {}
    for rel, lines in files.items():
        if rel.startswith("crates/sandslope-request/src"):
            for flag in ROW.findall("\n".join(lines)):
                homes.setdefault(flag, set()).add(rel)
    if not homes:
        print("no field tables found", file=sys.stderr)
        return 1
    found, pending = [], set()
    for rel, lines in files.items():
        if not rel.startswith(FRONT_ENDS):
            continue
        text = "\n".join(lines)
        hits = []
        for n, line in enumerate(lines, 1):
            named = set(NAMING.findall(line))
            for flag, tables in homes.items():
                if rel in tables or (rel, flag) in OTHER_MEANINGS:
                    continue
                if flag in named or f'"--{flag}"' in line:
                    hits.append(f"{rel}:{n}: the field `{flag}` spelled outside its table ({', '.join(sorted(tables))})")
        for m in DERIVE.finditer(text):
            flag = m.group(1).replace("_", "-")
            if flag in homes and (rel, flag) not in OTHER_MEANINGS:
                hits.append(f"{rel}:{line_of(text, m.start())}: a clap argument `--{flag}` beside the field's table")
        for m in DEFAULT_BY_NAME.finditer(text):
            if m.group(1) in homes and rel not in homes[m.group(1)]:
                hits.append(f"{rel}:{line_of(text, m.start())}: the field `{m.group(1)}`'s default read by name")
        if rel in PENDING:
            if hits:
                pending.add(rel)
        else:
            found.extend(hits)
    found.extend(page_findings(root, homes))
    found.extend(fuzz_findings(files, homes))
    found.extend(unknown_flag_findings(files, homes))
    for line in found:
        print(line)
    prose = prose_notes(files, homes)
    if prose:
        print(
            f"note: {len(prose)} message(s) spell a field's flag rather than taking it from the row "
            f"(FIELD.long()), first {prose[0]}; --verbose lists them",
            file=sys.stderr,
        )
        if "--verbose" in sys.argv:
            for line in prose:
                print(f"note: {line}", file=sys.stderr)
    for rel in sorted(pending):
        print(f"note: {rel} still names fields by their words: {PENDING[rel]}", file=sys.stderr)
    if found:
        print(f"{len(found)} field name(s), default(s) or argument(s) written outside the field tables", file=sys.stderr)
        return 1
    print(f"{len(homes)} field names, each written in its field table only ({len(pending)} file(s) pending)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
