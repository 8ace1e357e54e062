"""The README's Python example runs and prints what the README shows (on the shared data)."""

import contextlib
import io
import os
import re
import unittest

from support import DATA, main_needing

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")


class ReadmeExampleTest(unittest.TestCase):
    def test_the_example_prints_what_the_readme_shows(self):
        with open(README) as f:
            text = f.read()
        section = text[text.index("\n## Python\n"):]
        code, output = re.search(r"```python\n(.*?)```\s*```text\n(.*?)```", section, re.S).groups()
        self.assertLessEqual(len(code.strip().splitlines()), 10)
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code.replace("../shared/data", DATA), "README.md", "exec"), {})
        self.assertEqual(printed.getvalue(), output)


if __name__ == "__main__":
    main_needing(os.path.join(DATA, "evo"))
