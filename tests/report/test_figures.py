"""Every figure renders, and is not blank; keyframes come from a video when there is one."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")
from PIL import Image  # matplotlib brings Pillow

from fsvla.report import figures
from fsvla.report.keyframes import find_video, load_keyframes


def _pixels(png: bytes) -> np.ndarray:
    with Image.open(io.BytesIO(png)) as image:
        return np.asarray(image.convert("L"))


def _assert_drawn(figure, min_width: int = 400) -> None:
    png = figures.render(figure, "png", dpi=80)
    pixels = _pixels(png)
    assert pixels.shape[1] >= min_width
    assert (pixels < 128).mean() > 0.005  # ink: lines, text, markers
    assert len(np.unique(pixels)) > 10  # not a flat image
    assert figures.render(figure, "pdf").startswith(b"%PDF")
    assert b"<svg" in figures.render(figure, "svg")[:2000]


@pytest.mark.parametrize("name", ["landscape", "diagnosis"])
def test_overview_figures(report_data, name: str) -> None:
    _, report = report_data
    _assert_drawn(getattr(figures, name)(report))


def test_names_are_plain_text(report_data) -> None:
    _, report = report_data
    rows = tuple(r.model_copy(update={"label": f"cost $5 & {r.label} ${i}"})
                 for i, r in enumerate(report.aggregate.rows))
    odd = report.model_copy(update={"aggregate": report.aggregate.model_copy(
        update={"rows": rows})})
    _assert_drawn(figures.landscape(odd))  # an odd number of $ would fail as mathtext


def test_margins_figure(report_data) -> None:
    _, report = report_data
    figure = figures.margins(report.dissection)
    assert len(figure.axes) == 2  # one panel per channel
    _assert_drawn(figure)
    no_trace = report.dissection.model_copy(update={"margins": None})
    assert figures.margins(no_trace) is None and figures.keyframes(no_trace) is None


def test_written_figures(written: Path) -> None:
    for key in ("landscape", "diagnosis", "margins"):
        for fmt in ("png", "pdf", "svg"):
            assert (written / "figures" / f"{key}.{fmt}").stat().st_size > 1000
    assert not (written / "figures" / "keyframes.png").exists()  # no video recorded


def test_render_is_deterministic(report_data) -> None:
    _, report = report_data
    assert figures.render(figures.landscape(report), "pdf") == figures.render(
        figures.landscape(report), "pdf")


def _frames(count: int) -> list[Image.Image]:
    return [Image.fromarray(np.full((60, 80, 3), 20 * i, dtype=np.uint8)) for i in range(count)]


def test_keyframes_from_a_gif(tmp_path: Path, report_data) -> None:
    (tmp_path / "videos").mkdir()
    first, *rest = _frames(10)
    first.save(tmp_path / "videos" / "ep.gif", save_all=True, append_images=rest)
    found = load_keyframes(tmp_path, "ep", steps=20)
    assert found.source == "videos/ep.gif"
    assert [(k.frame, k.step) for k in found.frames] == [(0, 2), (3, 8), (6, 14), (9, 20)]
    _, report = report_data
    figure = figures.keyframes(report.dissection.model_copy(update={"keyframes": found}))
    assert len(figure.axes) == 4
    _assert_drawn(figure)


def test_keyframes_from_a_frame_folder(tmp_path: Path) -> None:
    folder = tmp_path / "frames" / "ep"
    folder.mkdir(parents=True)
    for i, frame in enumerate(_frames(3)):
        frame.save(folder / f"{i:04d}.png")
    found = load_keyframes(tmp_path, "ep", steps=3)
    assert [(k.frame, k.step) for k in found.frames] == [(0, 1), (1, 2), (2, 3)]
    assert find_video(tmp_path, "other") is None


def test_keyframes_from_an_mp4(tmp_path: Path) -> None:
    cv2 = pytest.importorskip("cv2")
    (tmp_path / "videos").mkdir()
    path = tmp_path / "videos" / "ep.mp4"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), 10, (80, 60))
    for frame in _frames(8):
        writer.write(np.asarray(frame)[:, :, ::-1].copy())
    writer.release()
    found = load_keyframes(tmp_path, "ep", steps=8)
    assert len(found.frames) == 4 and "keyframes of 8 frames" in found.note


def test_an_unreadable_video_is_reported_not_raised(tmp_path: Path) -> None:
    (tmp_path / "videos").mkdir()
    (tmp_path / "videos" / "ep.gif").write_bytes(b"not a gif")
    found = load_keyframes(tmp_path, "ep")
    assert found.frames == () and "could not be read" in found.note
