"""A labelled picture of a scenario's scene: its cameras plus a top-down view, with the
safety overlays (``fsvla.sim.overlays``) drawn into the scene.

``fsvla preview scenario.fsv -o preview.png`` calls :func:`render_preview`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import Pose
from fsvla.compiler.scene import SceneCamera, SceneSpec
from fsvla.dsl.models import Scenario

from .overlays import COLORS, add_overlays, scenario_overlays

TOP_CAMERA = "top"
#: (w, x, y, z) of a camera looking straight down with +x (forward) at the top of the image.
LOOK_DOWN = (math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0)
TOP_HEIGHT = 1.8  # m above the table top
TOP_MARGIN = 0.12  # m around the table and the robots' mounts
COLUMNS = 3
TITLE_HEIGHT = 28
LABEL_HEIGHT = 18
BACKGROUND = (24, 24, 28)
TEXT = (235, 235, 235)
LEGEND = (("hazard region", "region"), ("hard limit", "hard"), ("warning band", "warn"))


def layout(scenario: Scenario, level: str = "L0", seed: int = 0) -> tuple[Scenario, SceneSpec]:
    """The scenario (re-placed, tightened) and scene of one layout level and seed.

    L0 is the canonical layout (``lower_scene``); L1/L2 come from
    ``fsvla.compiler.variants.generate_variant`` (ValueError when it is missing)."""
    if level not in ("L0", "L1", "L2"):
        raise ValueError(f"unknown level {level!r}; levels: L0, L1, L2")
    if level == "L0":
        from fsvla.compiler.scene import lower_scene

        return scenario, lower_scene(scenario, seed=seed)
    try:
        from fsvla.compiler.variants import generate_variant
    except ImportError:
        raise ValueError(f"level {level} needs the variant generator (fsvla.compiler.variants), "
                         "which this installation lacks; only L0 can be previewed") from None
    variant = generate_variant(scenario, level, seed)
    return variant.scenario, variant.scene


def top_down_camera(spec: SceneSpec, width: int = 320, height: int = 240) -> SceneCamera:
    """A world camera above the table looking down, framing the table and the mounts
    (image up = +x, away from the main robot; image left = +y)."""
    xs, ys = [], []
    for body in spec.bodies:
        if body.support == "world":  # the table
            fp = body.asset.footprint
            xs += [body.pose.position[0] + fp.min_xy[0], body.pose.position[0] + fp.max_xy[0]]
            ys += [body.pose.position[1] + fp.min_xy[1], body.pose.position[1] + fp.max_xy[1]]
    for mount in spec.mounts:
        xs.append(mount.pose.position[0])
        ys.append(mount.pose.position[1])
    if not xs:
        xs, ys = [-0.5, 0.5], [-0.5, 0.5]
    cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    half_x = (max(xs) - min(xs)) / 2 + TOP_MARGIN  # image vertical
    half_y = (max(ys) - min(ys)) / 2 + TOP_MARGIN  # image horizontal
    aspect = width / height
    tan_half = max(half_x / TOP_HEIGHT, half_y / (TOP_HEIGHT * aspect))
    return SceneCamera(name=TOP_CAMERA, parent="world",
                       pose=Pose(position=(cx, cy, TOP_HEIGHT), quaternion=LOOK_DOWN),
                       fovy=2.0 * math.atan(tan_half), width=width, height=height,
                       near=0.05, far=TOP_HEIGHT - spec.ground_z + 1.0)


def render_preview(scenario: Scenario, spec: SceneSpec, *, overlays: bool = True,
                   shader: str = "minimal", shadows: bool | None = None,
                   view: str | None = None) -> Any:
    """The preview of ``spec`` (a layout of ``scenario``) as a PIL image: every camera of
    the spec plus :func:`top_down_camera`, overlays drawn when ``overlays``; with ``view``
    (a camera's name or ``top``), that view alone, with no title or label.

    Raises :class:`fsvla.sim.render.RenderUnavailable` without a Vulkan device, and
    ValueError for an unknown ``view``."""
    names = [camera.name for camera in spec.cameras] + [TOP_CAMERA]
    if view is not None and view not in names:
        raise ValueError(f"--view {view}: not a view of {spec.scenario} "
                         f"(its views: {', '.join(names)})")
    from .builder import build
    from .render import mount_camera

    built = build(spec, render=True, shader=shader, shadows=shadows)
    if overlays:
        add_overlays(built.scene, scenario_overlays(scenario, spec))
    first = spec.cameras[0] if spec.cameras else None
    top = top_down_camera(spec, first.width if first else 320, first.height if first else 240)
    built.cameras[TOP_CAMERA] = mount_camera(built.scene, top, shader, {})
    views = built.render_views()
    if view is not None:
        from PIL import Image

        return Image.fromarray(views[view])
    title = (f"{spec.scenario}  {spec.level} seed {spec.seed}  {spec.embodiment.name}  "
             f"shader {shader}" + ("" if overlays else "  (no overlays)"))
    return compose_grid(views, title, legend=overlays)


def compose_grid(views: Mapping[str, NDArray[np.uint8]], title: str, *,
                 legend: bool = True, columns: int = COLUMNS) -> Any:
    """The views as a grid of labelled tiles under a title line (and a colour legend)."""
    from PIL import Image, ImageDraw

    if not views:
        raise ValueError("no views to compose")
    tile_w = max(v.shape[1] for v in views.values())
    tile_h = max(v.shape[0] for v in views.values())
    cols = min(columns, len(views))
    size = grid_size(len(views), tile_w, tile_h, columns)
    canvas = Image.new("RGB", size, BACKGROUND)
    draw = ImageDraw.Draw(canvas)
    draw.text((6, 8), title, fill=TEXT)
    if legend:
        x = size[0] - 6
        for text, kind in reversed(LEGEND):
            x -= int(draw.textlength(text)) + 6
            draw.text((x, 8), text, fill=TEXT)
            x -= 16
            color = tuple(int(255 * c) for c in COLORS[kind][:3])
            draw.rectangle((x, 8, x + 12, 20), fill=color)
            x -= 10
    for index, (name, view) in enumerate(views.items()):
        row, col = divmod(index, cols)
        left = col * tile_w
        top = TITLE_HEIGHT + row * (tile_h + LABEL_HEIGHT)
        label = f"{name}  {view.shape[1]}x{view.shape[0]}"
        draw.text((left + 4, top + 3), label, fill=TEXT)
        canvas.paste(Image.fromarray(view), (left, top + LABEL_HEIGHT))
    return canvas


def grid_size(count: int, tile_w: int, tile_h: int, columns: int = COLUMNS) -> tuple[int, int]:
    """(width, height) of :func:`compose_grid`'s picture for ``count`` tiles."""
    cols = min(columns, count)
    rows = math.ceil(count / cols)
    return cols * tile_w, TITLE_HEIGHT + rows * (tile_h + LABEL_HEIGHT)


__all__ = ["TOP_CAMERA", "compose_grid", "grid_size", "layout", "render_preview", "top_down_camera"]
