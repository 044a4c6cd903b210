"""The README's examples run as printed: the ten-line 2-D example and its 3-D sequel."""
import re
from pathlib import Path

import numpy as np


def test_the_readme_examples_run():
    text = (Path(__file__).parents[1] / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    scope: dict = {}
    for code in blocks:  # in order: the 3-D example uses the 2-D one's imports
        exec(compile(code, "README.md", "exec"), scope)  # noqa: S102
    assert np.all(np.isfinite(scope["u_tip"])) and scope["u_tip"][0][1] < 0.0
    top = scope["sol3"].displacement([[0.2, 0.2, 1.0]])
    assert np.all(np.isfinite(top)) and top[0][2] < 0.0
