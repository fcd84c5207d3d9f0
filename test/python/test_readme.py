"""The README's "From Python" loop runs as written (from the repository root, as a reader runs it) and does
what the README says it does: the rope's middle node ends within a centimetre of the target."""
import re

import numpy as np

from conftest import ROOT


def readme_python_block():
    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## From Python\n", 1)[1].split("\n## ", 1)[0]
    [block] = re.findall(r"```python\n(.*?)```", section, re.S)
    return block


def test_the_readme_mppi_loop_runs_as_written_and_reaches_its_target(monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    scope = {}
    exec(compile(readme_python_block(), "README.md (From Python)", "exec"), scope)
    assert "cm from the target" in capsys.readouterr().out
    assert np.linalg.norm(scope["w"].positions()[scope["middle"]] - scope["target"]) < 0.01
