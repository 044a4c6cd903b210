"""The README's ten-line example runs as printed."""
import re
from pathlib import Path

import numpy as np


def test_the_readme_example_runs():
    text = (Path(__file__).parents[1] / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)  # noqa: S102
    assert np.all(np.isfinite(scope["u_tip"])) and scope["u_tip"][0][1] < 0.0
