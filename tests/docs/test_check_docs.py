#!/usr/bin/env python3
"""check_docs.py can fail: on a small tree of its own, a doc that names a missing identifier, path, link
or flag is reported, and an undocumented flag is too. Stdlib unittest (pytest runs it as well):

    python3 tests/docs/test_check_docs.py
"""

import contextlib
import io
import os
import stat
import sys
import tempfile
import textwrap
import unittest

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_docs  # noqa: E402

TOP_HELP = """\
candela: a test double.
Usage: candela [OPTIONS] [SUBCOMMAND]

Options:
  -h,--help                   Print this help message and exit
  --version                   Display program version information and exit

Subcommands:
  render                      Render a scene file to an image
  merge                       Put the parts together
"""
RENDER_HELP = """\
Render a scene file to an image
Usage: candela render [OPTIONS] scene

Positionals:
  scene TEXT REQUIRED         Scene file

Options:
  -h,--help                   Print this help message and exit
  -o,--output TEXT            Output image (mentions --not-an-option in its text)
  --spp INT                   Samples per pixel
  --secret-flag               A flag the docs do not name
"""
MERGE_HELP = """\
Put the parts together
Usage: candela merge [OPTIONS] parts...

Options:
  -h,--help                   Print this help message and exit
  -o,--output TEXT REQUIRED   The image to write
"""

SOURCE = """\
// The renderer's only source.
struct RealType { int real_member; };
void real_function(const RealType&) {}
static const char* kKeys[] = {"to_world", "emission"};
"""

GOOD_DOC = """\
# A doc that names only what exists

`real_function()` takes a `RealType`; `RealType::real_member` and `to_world` exist, as do
`src/candela/scene/thing.cpp`, `scene/thing.cpp`, `scene/` and `thing.cpp`. Not candela's: `--spp 64`,
`FOO_BAR=1`, `42`, `https://example.org/a_b`, `np.mean(x)`, `std::not_a_thing`, pbrt-v4's
`SomeOtherClass`, `../shared/meshes/none.ply`. See [cli](cli.md).

```
candela render scene.json --spp 4 -o out.exr
```
"""

BAD_DOC = """\
# A doc that has drifted

The function is `missing_function` (it was renamed).
The type `MissingType` and the member `RealType::gone_member` are gone; `RealType::other_member` and
the test `RealType.OtherType` never were (each part exists, in different files).
A call: `vanished()`. A file: `src/candela/scene/nope.cpp`, and `scene/nope.h`.
A broken [link](nowhere.md).

```
candela render scene.json --no-such-flag
```
"""

CLI_DOC = """\
# Command line

`candela render SCENE`: `--spp N`, `-o, --output FILE`. `candela merge`. `--help`, `--version`.
"""


class CheckDocsTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.src = self.dir.name
        self.write("src/candela/scene/thing.cpp", SOURCE)
        self.write("tests/other_test.cpp", "struct OtherType { int other_member; };\n")
        self.write("docs/good.md", GOOD_DOC)
        self.write("docs/cli.md", CLI_DOC)
        candela = self.write("fake_candela", textwrap.dedent(f"""\
            #!{sys.executable}
            import sys
            texts = {{(): {TOP_HELP!r}, ("render",): {RENDER_HELP!r}, ("merge",): {MERGE_HELP!r}}}
            print(texts[tuple(a for a in sys.argv[1:] if a != "--help")], end="")
            """))
        os.chmod(candela, os.stat(candela).st_mode | stat.S_IXUSR)
        self.candela = candela

    def tearDown(self):
        self.dir.cleanup()

    def write(self, rel, text):
        path = os.path.join(self.src, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_check(self, *extra):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = check_docs.main([self.src, self.candela, *extra])
        return code, out.getvalue().splitlines()

    def test_names_that_exist_pass(self):
        code, lines = self.run_check("--only", "identifiers")
        self.assertEqual(lines, [])
        self.assertEqual(code, 0)

    def test_drift_is_reported_one_line_each(self):
        self.write("docs/bad.md", BAD_DOC)
        self.write("docs/cli.md", CLI_DOC + "`--removed-flag N` is no longer there.\n")
        code, lines = self.run_check("--only", "identifiers")
        self.assertEqual(code, 1)
        self.assertEqual(sorted(lines), sorted([
            "docs/bad.md:3: identifier 'missing_function' not found in the tree",
            "docs/bad.md:4: identifier 'MissingType' not found in the tree",
            "docs/bad.md:4: identifier 'RealType::gone_member' not found in the tree",
            "docs/bad.md:4: identifier 'RealType::other_member' not found in the tree",
            "docs/bad.md:5: identifier 'RealType.OtherType' not found in the tree",
            "docs/bad.md:6: identifier 'vanished' not found in the tree",
            "docs/bad.md:6: path 'src/candela/scene/nope.cpp' not found in the tree",
            "docs/bad.md:6: path 'scene/nope.h' not found in the tree",
            "docs/bad.md:7: link target 'nowhere.md' not found",
            "docs/bad.md:10: flag '--no-such-flag' is not in candela's --help",
            "docs/cli.md:4: flag '--removed-flag' is not in candela's --help",
        ]))

    def test_undocumented_flags_and_subcommands_are_reported(self):
        code, lines = self.run_check("--only", "flags")
        self.assertEqual(code, 1)
        self.assertEqual(lines, ["docs/cli.md:1: flag '--secret-flag' of 'candela render' is not documented"])
        self.write("docs/cli.md", CLI_DOC.replace("`candela merge`", "merging"))
        code, lines = self.run_check("--only", "flags")
        self.assertIn("docs/cli.md:1: subcommand 'candela merge' is not documented", lines)

    def test_help_parsing_takes_the_option_column_only(self):
        flags = check_docs.help_flags(self.candela)
        self.assertEqual(flags, {"": ["--help", "--version"],
                                 "render": ["--help", "--output", "--spp", "--secret-flag"],
                                 "merge": ["--help", "--output"]})

    def test_a_stale_external_entry_is_reported(self):
        saved = dict(check_docs.EXTERNAL)
        check_docs.EXTERNAL["real_function"] = "not external at all"
        try:
            code, lines = self.run_check("--only", "identifiers")
        finally:
            check_docs.EXTERNAL.clear()
            check_docs.EXTERNAL.update(saved)
        self.assertEqual(code, 1)
        self.assertEqual(lines, ["tests/docs/check_docs.py:1: EXTERNAL lists 'real_function', which is in "
                                 "the tree now"])

    def test_classify(self):
        paths, names, flags = check_docs.classify(
            "mpirun -np 2 build/candela render x.json --spp 8 # io/gzip.h `HostileInput.FullDisk`")
        self.assertEqual(flags, ["--spp"])
        paths, names, flags = check_docs.classify("bench/run.py --candela build/candela --repeats 3")
        self.assertEqual(flags, [])
        self.assertEqual(paths, ["bench/run.py", "build/candela"])
        paths, names, flags = check_docs.classify("HostileInput.FullDisk and Scene::shading(hit)")
        self.assertEqual(names, ["Scene::shading", "HostileInput.FullDisk"])
        paths, names, flags = check_docs.classify("-DCANDELA_BUILD_PYTHON=OFF -fPIC TSAN_TESTS=x .ci/tsan")
        self.assertEqual((paths, names), ([".ci/tsan"], ["CANDELA_BUILD_PYTHON"]))
        paths, names, flags = check_docs.classify("cannot read 'textures/wood.png' or 'meshes/cow.obj'")
        self.assertEqual((paths, names), ([], []))


if __name__ == "__main__":
    unittest.main()
