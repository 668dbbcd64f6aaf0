"""What pressed when a contact-force limit was crossed: the replay behind FSV712's note."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsvla.cli import run
from fsvla.validate.crossing import Crossing, Crossings

from .test_command import WEAK_GRIP


def test_a_crossing_reads_as_what_pressed_on_what() -> None:
    grip = Crossing(step=109, subject="gripper", force=2.05, other="`cube`", touching=(), held=None)
    assert grip.text() == "`gripper` against `cube`, 2.05 N, at step 109"
    knock = Crossing(step=350, subject="bottle", force=393.356, other=None,
                     touching=("`table`",), held=False)
    assert knock.text() == ("`bottle` knocked, 393.36 N of net contact force (from its change of "
                            "speed), touching `table`, not in the gripper, at step 350")
    assert Crossings(grip, grip).text() == "what pressed: `gripper` against `cube`, 2.05 N, at step 109"
    assert Crossings(grip, knock).text().startswith("what pressed: first `gripper` against `cube`, "
                                                    "2.05 N, at step 109; hardest `bottle` knocked")


@pytest.mark.sim
def test_a_crossed_grip_limit_says_the_fingers_pressed_on_the_cube(tmp_path: Path, capsys) -> None:
    path = tmp_path / "weak_grip.fsv"
    path.write_text(WEAK_GRIP, encoding="utf-8")
    args = ["validate", str(path), "--seeds", "1", "--levels", "L0", "--workers", "0",
            "--format", "json", "--out", str(tmp_path / "runs")]
    assert run(args) == 1
    report = json.loads(capsys.readouterr().out)
    crossed = next(d for d in report["diagnostics"] if d["code"] == "FSV712")
    pressed = [note for note in crossed["notes"] if note.startswith("what pressed: ")]
    assert len(pressed) == 1
    assert pressed[0].startswith("what pressed: first `gripper` against `cube`, ")
    assert "; hardest `gripper` against `cube`, " in pressed[0]
