#!/usr/bin/env python3
"""Tests of scripts/readme_check.py on small fixture markdown files and a
fake app (a shell script) whose timings change on every run."""

import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

CHECKER = Path(__file__).resolve().parent.parent / "scripts" / "readme_check.py"

# Prints a result (its argument), a timing that differs on every run, an
# error on stderr for a negative argument, and writes out/fake.txt and a
# file in the working directory.
FAKE_APP = r"""#!/usr/bin/env bash
n=$1
if [ "$n" -lt 0 ]; then echo "fakeapp: $n: must be >= 0" >&2; exit 2; fi
echo "fakeapp: $n landings in 0.$RANDOM s ($RANDOM landings/s)"
echo "  result $n items, mean 0.125 m"
echo '{"count":'"$n"',"seconds":0.'"$RANDOM"'}'
echo written > out/fake.txt
echo written > here.txt
"""

DOC = """# Fixture

Text before, kept as it is.

```
$ fakeapp 3
fakeapp: 3 landings in 0.101 s (4242 landings/s)
  result 3 items, mean 0.125 m
{"count":3,"seconds":0.5}
$ fakeapp -1; echo "exit $?"
exit 2
fakeapp: -1: must be >= 0
$ fakeapp \\
      4 | head -1
fakeapp: 4 landings in 1.5 s (7 landings/s)
```

<!-- readme-check: skip (needs the reader's file) -->
```
$ fakeapp my_file.yaml
anything
```

```
$ not_an_app --help
whatever
```

Text after.
"""


class ReadmeCheckTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        base = Path(self.tmp.name)
        self.root = base / "repo"
        self.root.mkdir()
        self.bin = base / "bin"
        self.bin.mkdir()
        app = self.bin / "fakeapp"
        app.write_text(FAKE_APP)
        app.chmod(0o755)
        self.doc = self.root / "DOC.md"

    def tearDown(self):
        self.tmp.cleanup()

    def check(self, text, *extra):
        self.doc.write_text(text)
        return subprocess.run(
            [sys.executable, str(CHECKER), "--bin", str(self.bin), "--root", str(self.root), str(self.doc), *extra],
            capture_output=True,
            text=True,
        )

    def test_passes_when_only_timings_differ(self):
        r = self.check(DOC)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("3 of 3 commands match, 2 skipped", r.stdout)
        self.assertIn("needs the reader's file", r.stdout)
        self.assertIn("'not_an_app' is not an app", r.stdout)

    def test_a_timing_column_may_change_its_width(self):
        # led_pose benchmark's last column, ms/frame, padded to its width.
        sys.path.insert(0, str(CHECKER.parent))
        import readme_check  # noqa: E402

        row = "paper chase     harsh    moving    aruco      300    0.463        69        0.1001 {}"
        self.assertEqual(readme_check.normalize(row.format("      5.209")), readme_check.normalize(row.format("     10.547")))
        # A result is still strict.
        self.assertNotEqual(
            readme_check.normalize(row.format("5.209")), readme_check.normalize(row.replace("69", "70").format("5.209"))
        )

    def test_fails_on_a_changed_result(self):
        r = self.check(DOC.replace("result 3 items", "result 2 items"))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("FAIL  DOC.md:6: $ fakeapp 3", r.stdout)
        self.assertIn("-   result 2 items, mean 0.125 m", r.stdout)
        self.assertIn("+   result 3 items, mean 0.125 m", r.stdout)

    def test_a_number_outside_the_timing_table_is_strict(self):
        r = self.check(DOC.replace("mean 0.125 m", "mean 0.126 m"))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        r = self.check(DOC.replace('{"count":3,', '{"count":4,'))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)

    def test_fails_on_a_changed_error_message_and_a_missing_line(self):
        r = self.check(DOC.replace("must be >= 0", "must be > 0"))
        self.assertEqual(r.returncode, 1)
        r = self.check(DOC.replace("exit 2\n", ""))
        self.assertEqual(r.returncode, 1)

    def test_order_within_a_stream_is_checked(self):
        swapped = DOC.replace(
            "  result 3 items, mean 0.125 m\n{\"count\":3,\"seconds\":0.5}",
            "{\"count\":3,\"seconds\":0.5}\n  result 3 items, mean 0.125 m",
        )
        self.assertEqual(self.check(swapped).returncode, 1)

    def test_update_rewrites_only_outputs_and_keeps_matching_lines(self):
        stale = DOC.replace("result 3 items", "result 9 items")
        r = self.check(stale, "--update")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        # The stale line is fixed; every other line, timings included, is unchanged.
        self.assertEqual(self.doc.read_text(), DOC)
        self.assertEqual(self.check(self.doc.read_text()).returncode, 0)

    def test_update_timings_refreshes_the_timings(self):
        r = self.check(DOC, "--update", "--update-timings")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        text = self.doc.read_text()
        self.assertNotIn("0.101 s (4242 landings/s)", text)
        self.assertTrue(text.startswith("# Fixture\n\nText before, kept as it is.\n\n```\n$ fakeapp 3\n"))
        self.assertTrue(text.endswith("```\n$ not_an_app --help\nwhatever\n```\n\nText after.\n"))
        self.assertEqual(self.check(text).returncode, 0)

    def test_commands_write_nothing_into_the_repository(self):
        (self.root / "out").mkdir()
        self.assertEqual(self.check(DOC).returncode, 0)
        self.assertEqual(sorted(p.name for p in self.root.iterdir()), ["DOC.md", "out"])
        self.assertEqual(list((self.root / "out").iterdir()), [])

    def test_list_prints_every_command_with_its_line(self):
        r = self.check(DOC, "--list")
        self.assertEqual(r.returncode, 0)
        self.assertIn("DOC.md:6: $ fakeapp 3\n", r.stdout)
        self.assertIn("DOC.md:13: $ fakeapp \\\n      4 | head -1\n", r.stdout)
        self.assertIn("[skip: needs the reader's file]", r.stdout)


if __name__ == "__main__":
    unittest.main()
