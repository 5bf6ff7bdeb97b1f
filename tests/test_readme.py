"""The README's Python snippets run as written (issue 17 items 12 and 13)."""
import re
from pathlib import Path

import numpy as np

README = (Path(__file__).resolve().parents[1] / "README.md").read_text()


def section(title):
    start = README.index(f"## {title}")
    end = README.index("\n## ", start + 1)
    return README[start:end]


def test_modelling_cables_snippet_runs():
    code = re.findall(r"```python\n(.*?)```", section("Modelling cables"), flags=re.S)[0]
    ns = {}
    exec(compile(code, "README.md", "exec"), ns)
    force, torque = ns["force"], ns["torque"]
    # 1e-4 strain of the 1+6 strand at 10 degrees: the example's table, 4.2657e6 N and 1279.9 N m
    assert np.isclose(force / 1e-4, 4.2657e6, rtol=0.01) and np.isclose(torque / 1e-4, 1279.9, rtol=0.01)


def test_stepwriter_snippet_runs(tmp_path, monkeypatch):
    import beamsolver as bs
    line = re.search(r"output=(bs\.io\.vtk\.StepWriter\(\"out\", refine=4,\s*compression=None\))", README).group(1)
    monkeypatch.chdir(tmp_path)
    writer = eval(line, {"bs": bs})
    assert writer.refine == 4 and writer.compression is None and writer.folder.name == "out"
