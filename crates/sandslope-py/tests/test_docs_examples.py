"""The Python the README and the docs show, run as written (issue 28): every ```python block
of docs/*.md and README.md, and every `python -c "..."` line of their ```sh blocks (the
`sandslope` commands are run by crates/sandslope-cli/tests/it/docs_examples.rs)."""

import re
import runpy
import shlex

import pytest

from conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)


def _snippets():
    out = []
    for doc in DOCS:
        text = doc.read_text()
        for m in FENCE.finditer(text):
            lang, body = m.group(1), m.group(2)
            where = f"{doc.relative_to(ROOT)}:{text[: m.start()].count(chr(10)) + 1}"
            if lang == "python":
                out.append(pytest.param(body, id=where))
            elif lang in ("sh", "bash"):
                for line in body.splitlines():
                    if line.startswith("python -c "):
                        code = shlex.split(line, comments=True)[2]
                        out.append(pytest.param(code, id=where))
    return out


SNIPPETS = _snippets()


def test_the_docs_show_python_to_run():
    # A parser that finds nothing would make the test below pass vacuously.
    assert len(SNIPPETS) >= 2


# A warning in a worked example is a worked example that misleads (issue 41): an error here.
@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("code", SNIPPETS)
def test_doc_python_runs_as_written(code, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    script = tmp_path / "snippet.py"
    script.write_text(code)
    runpy.run_path(str(script), run_name="__main__")
