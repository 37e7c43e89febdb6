"""render()'s keywords come from the render option table (description/render_options.h), as the
command line's flags do: an option added to the table is a keyword here with no other edit."""
import subprocess

import pytest

import candela
from candela import _candela
from conftest import CLI, furnace_dict


def test_every_option_of_the_table_is_a_keyword_and_nothing_else_is():
    table = _candela.render_options()
    assert table, "the table is empty"
    keywords = candela.render_keywords()
    assert set(keywords) == {name for name, _, _, python in table if python}


def test_every_keyword_is_the_flag_of_the_same_option():
    help_text = subprocess.run([CLI, "render", "--help"], capture_output=True, text=True, check=True).stdout
    for name, flag, _, python in _candela.render_options():
        assert flag == "--" + name.replace("_", "-")
        assert flag in help_text


@pytest.mark.parametrize("keyword, value, message", [
    ("spp", 0, "spp: 0 is out of range"),
    ("rr_start_depth", -1, "rr_start_depth: -1 is out of range"),
    ("sampler", "sobol", "sampler: unknown value .sobol."),
])
def test_keywords_are_checked_by_the_table_with_the_flags_message(keyword, value, message):
    with pytest.raises(candela.UsageError, match=message):
        candela.render(candela.load_dict(furnace_dict()), **{keyword: value})
