"""rjcad.io.console: the console examples of the pages rjcad generates are run as the docs' tests run them and
cut to the lines a page shows, `...` for each run of lines left out."""

import pytest

from rjcad.io import console


def test_cut_marks_each_run_of_left_out_lines_once():
    lines = ["a", "b  ", "c", "d", "e"]
    assert console.cut(lines, None) == ["a", "b", "c", "d", "e"]
    assert console.cut(lines, lambda i, _: i in (0, 3)) == ["a", "...", "d", "..."]
    assert console.cut(lines, console.containing("c", "e")) == ["...", "c", "...", "e"]
    assert console.cut(lines, console.first(2)) == ["a", "b", "..."]


def test_a_block_is_the_commands_real_output_with_its_exit_code(tmp_path):
    assert console.block("rjcad spring --stiffness -1", tmp_path, exit_code=2) == [
        "<!-- example: exit=2 -->",
        "```console",
        "$ rjcad spring --stiffness -1",
        "rjcad: error: stiffness = -1 is invalid: must be >= 0.01 and <= 10000 N·mm/rad (joint, both springs)",
        "```",
    ]
    with pytest.raises(RuntimeError, match="exited with 2, not 0"):
        console.block("rjcad spring --stiffness -1", tmp_path)
    with pytest.raises(ValueError, match="not an rjcad command"):
        console.run("ls", tmp_path)
