"""`fsvla preview`: overlay geometry (plain data), the grid, and a rendered preview whose
hazard overlay shows where the stove is."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fsvla.compiler.scene import lower_scene

from fsvla.cli import run
from fsvla.sim.overlays import CORNER_SAMPLES, Outline, scenario_overlays
from fsvla.sim.preview import (
    LABEL_HEIGHT,
    TITLE_HEIGHT,
    compose_grid,
    grid_size,
    layout,
    top_down_camera,
)

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
STOVE = SCENARIOS / "thermal" / "lift_pot_beside_stove.fsv"


@pytest.fixture(scope="module")
def stove(load_scenario):
    scenario = load_scenario(STOVE)
    return scenario, lower_scene(scenario)


def test_outline_offsets_pair_up() -> None:
    rect = Outline((0.1, 0.2), math.pi / 2, 0.0, half=(0.09, 0.05))
    disc = Outline((0.0, 0.0), 0.0, 0.0, radius=0.05)
    for outline in (rect, disc):
        inner, outer = outline.points(0.0), outline.points(0.06)
        assert inner.shape == outer.shape == (4 * CORNER_SAMPLES, 2)
    # yaw 90 deg swaps the rectangle's extents; growing by d adds d on every side
    grown = rect.points(0.06)
    assert np.allclose(grown.max(axis=0) - grown.min(axis=0), [2 * 0.11, 2 * 0.15])
    assert np.allclose(np.linalg.norm(disc.points(0.06), axis=1), 0.11)


def test_stove_overlays(stove) -> None:
    scenario, spec = stove
    overlays = scenario_overlays(scenario, spec)
    kinds = {(o.name, o.kind): o for o in overlays}
    assert ("stove", "region") in kinds
    # keep gripper, pot outside 6 cm warn 4 cm: red to 6 cm, amber from 6 to 10 cm
    assert (kinds[("stove", "hard")].inner, kinds[("stove", "hard")].outer) == (0.0, 0.06)
    warn = kinds[("stove", "warn")]
    assert warn.inner == pytest.approx(0.06) and warn.outer == pytest.approx(0.10)
    assert ("stove#2", "hard") in kinds and ("stove#2", "warn") in kinds
    region = kinds[("stove", "region")].outline
    assert region.center == pytest.approx((0.30, 0.0)) and region.half == pytest.approx((0.09, 0.09))
    for overlay in overlays:
        vertices, faces = overlay.mesh()
        assert faces.max() < len(vertices) and vertices[:, 2].min() > 0.002  # above the marker


def test_grid_layout() -> None:
    views = {name: np.full((240, 320, 3), i * 40, np.uint8) for i, name in enumerate("abcd")}
    image = compose_grid(views, "title")
    assert image.size == grid_size(4, 320, 240) == (960, TITLE_HEIGHT + 2 * (240 + LABEL_HEIGHT))
    pixel = image.getpixel((320 + 10, TITLE_HEIGHT + LABEL_HEIGHT + 10))
    assert pixel == (40, 40, 40)


def test_top_camera_frames_the_table(stove) -> None:
    _, spec = stove
    camera = top_down_camera(spec)
    z = camera.pose.position[2]
    half_y = math.tan(camera.fovy / 2) * z  # image vertical = world x
    assert half_y * camera.width / camera.height >= 0.6 + 0.1  # the dual arms at y = +-0.6
    assert half_y >= 0.6  # the table's half length along x


def test_levels_go_through_the_variant_generator(stove) -> None:
    scenario, _ = stove
    varied, scene = layout(scenario, "L2", 3)
    assert (scene.level, scene.seed) == ("L2", 3) and varied.name == scenario.name
    with pytest.raises(ValueError, match="unknown level"):
        layout(scenario, "L9", 0)


def _pixel(camera, point) -> tuple[int, int]:
    """(column, row) of a world point in the top-down camera's picture."""
    cx, cy, cz = camera.pose.position
    f = (camera.height / 2) / math.tan(camera.fovy / 2)
    depth = cz - point[2]
    col = camera.width / 2 - f * (point[1] - cy) / depth
    row = camera.height / 2 - f * (point[0] - cx) / depth
    return int(col), int(row)


@pytest.mark.sim
@pytest.mark.render
def test_preview_draws_overlays(render_device, stove, tmp_path: Path) -> None:
    from PIL import Image

    from fsvla.sim.preview import render_preview

    scenario, spec = stove
    out = tmp_path / "preview.png"
    assert run(["preview", str(STOVE), "-o", str(out)]) == 0
    with_overlays = np.asarray(Image.open(out).convert("RGB"), dtype=np.int16)
    plain = np.asarray(render_preview(scenario, spec, overlays=False), dtype=np.int16)
    views = len(spec.cameras) + 1
    assert with_overlays.shape == plain.shape == (*grid_size(views, 320, 240)[::-1], 3)
    # The top view is the last tile: row 1, column 0 of a 3-column grid (4 views).
    top = top_down_camera(spec)
    row, col = divmod(views - 1, 3)
    x0, y0 = col * 320, TITLE_HEIGHT + row * (240 + LABEL_HEIGHT) + LABEL_HEIGHT

    def patch(image: np.ndarray, point) -> np.ndarray:
        u, v = _pixel(top, point)
        return image[y0 + v - 2:y0 + v + 3, x0 + u - 2:x0 + u + 3]

    stove_xy = spec.zone("stove").pose.position
    band = (stove_xy[0] + 0.09 + 0.03, stove_xy[1], 0.0)  # inside the red 6 cm band
    for point in (stove_xy, band):
        assert np.abs(patch(with_overlays, point) - patch(plain, point)).mean() > 15, point
    far = (-0.45, 0.3, 0.0)  # a table corner, far from every overlay
    assert np.abs(patch(with_overlays, far) - patch(plain, far)).mean() < 2


@pytest.mark.sim
def test_preview_without_device_fails_cleanly(tmp_path: Path) -> None:
    env = {**os.environ, "VK_ICD_FILENAMES": "/nonexistent/icd.json"}
    done = subprocess.run([sys.executable, "-m", "fsvla", "preview", str(STOVE), "-o",
                           str(tmp_path / "p.png")], check=False, capture_output=True, text=True, env=env,
                          timeout=120)
    assert done.returncode == 1
    assert "no Vulkan rendering device" in done.stderr and ".ci/install-vulkan" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    assert not (tmp_path / "p.png").exists()


@pytest.mark.sim
@pytest.mark.render
def test_preview_one_view_by_built_in_name(render_device, tmp_path: Path, capsys) -> None:
    """`--view` writes that view alone, at the camera's size; a scenario may be named."""
    from PIL import Image

    out = tmp_path / "front.png"
    assert run(["preview", STOVE.stem, "--view", "front", "-o", str(out)]) == 0
    assert Image.open(out).size == (320, 240)
    assert run(["preview", STOVE.stem, "--view", "side", "-o", str(tmp_path / "x.png")]) == 1
    assert "its views: front, left_wrist, right_wrist, top" in capsys.readouterr().err
    assert run(["preview", "suite:thermal", "-o", str(tmp_path / "y.png")]) == 2
