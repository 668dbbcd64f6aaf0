"""Safety overlays: where a scenario's hazards and keep-out bands lie, as flat shapes.

An :class:`Outline` is a convex footprint on a surface (a rectangle or a disc, world
frame). A scenario's overlays (:func:`scenario_overlays`) are:

- ``region``: each zone's monitored region (a corridor's: its walls, the hazard);
- ``hard``: for each ``zone_distance``/``clearance`` limit that keeps something at least
  ``limit`` from a zone or object, the band from the footprint out to ``limit``;
- ``warn``: the band from ``limit`` out to ``limit + soft_threshold`` (the warning zone).

Plain data and numpy only; :func:`add_overlays` puts them into a rendered SAPIEN scene
as translucent, visual-only geometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.assets.model import Pose
from fsvla.compiler.pose import quat_yaw, rotate_xy
from fsvla.compiler.scene import SceneSpec
from fsvla.dsl.models import Scenario

OverlayKind = Literal["region", "hard", "warn"]

#: RGBA of each overlay kind (translucent).
COLORS: dict[str, tuple[float, float, float, float]] = {
    "region": (0.9, 0.1, 0.9, 0.6),
    "hard": (1.0, 0.05, 0.05, 0.6),
    "warn": (1.0, 0.7, 0.0, 0.6),
}
#: Height of the overlays above their surface (above the 2 mm zone markers), and
#: their thickness; each further limit on one reference is stacked LAYER higher.
LIFT, THICKNESS, LAYER = 0.003, 0.001, 0.0015
CORNER_SAMPLES = 8
METRICS = ("zone_distance", "clearance")


@dataclass(frozen=True)
class Outline:
    """A convex footprint on a surface: a rectangle (``half``) or a disc (``radius``)."""

    center: tuple[float, float]
    yaw: float
    z: float
    half: tuple[float, float] | None = None
    radius: float | None = None

    def points(self, offset: float) -> NDArray[np.float64]:
        """The outline grown by ``offset`` (rounded corners), world xy, counter-clockwise,
        always ``4 * CORNER_SAMPLES`` points so that two offsets pair up point by point."""
        n = CORNER_SAMPLES
        if self.radius is not None:
            angles = np.linspace(0.0, 2.0 * math.pi, 4 * n, endpoint=False)
            local = (self.radius + offset) * np.stack([np.cos(angles), np.sin(angles)], axis=1)
        else:
            hx, hy = self.half  # type: ignore[misc]
            corners = ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))
            local = np.concatenate([
                np.asarray(c) + offset * np.stack(
                    [np.cos(a := np.linspace(k * math.pi / 2, (k + 1) * math.pi / 2, n)),
                     np.sin(a)], axis=1)
                for k, c in enumerate(corners)])
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        rotated = local @ np.array([[c, s], [-s, c]])
        return rotated + np.asarray(self.center)


@dataclass(frozen=True)
class Overlay:
    """A flat band between two offsets of an outline (``inner`` None: filled)."""

    name: str
    kind: OverlayKind
    outline: Outline
    inner: float | None
    outer: float
    layer: int = 0

    def mesh(self) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        """Vertices (world) and triangles of the band: a top face and a bottom face."""
        outer = self.outline.points(self.outer)
        inner = (np.repeat(np.asarray(self.outline.center)[None], len(outer), axis=0)
                 if self.inner is None else self.outline.points(self.inner))
        z0 = self.outline.z + LIFT + self.layer * LAYER
        n = len(outer)
        top = np.concatenate([np.c_[inner, np.full(n, z0 + THICKNESS)],
                              np.c_[outer, np.full(n, z0 + THICKNESS)]])
        bottom = top.copy()
        bottom[:, 2] = z0
        vertices = np.concatenate([top, bottom])
        faces = []
        for i in range(n):
            j = (i + 1) % n
            faces += [(i, n + i, n + j), (i, n + j, j)]  # top, facing +z
            faces += [(2 * n + i, 2 * n + j, 3 * n + j), (2 * n + i, 3 * n + j, 3 * n + i)]
        return vertices, np.asarray(faces, dtype=np.int64)


def _shape_outline(shape: Any, frame: Pose) -> Outline | None:
    """The footprint of a box or cylinder shape given in ``frame`` (a yaw-only pose)."""
    yaw = quat_yaw(frame.quaternion)
    dx, dy = rotate_xy(shape.pose.position, yaw)
    center = (frame.position[0] + dx, frame.position[1] + dy)
    z = frame.position[2]
    if shape.type == "box":
        return Outline(center, yaw + quat_yaw(shape.pose.quaternion), z,
                       half=(shape.half_size[0], shape.half_size[1]))
    if shape.type in ("cylinder", "capsule", "sphere"):
        return Outline(center, yaw, z, radius=shape.radius)
    return None


def reference_outlines(spec: SceneSpec, name: str) -> list[Outline]:
    """The footprints a limit's ``reference`` names: a zone's region (a corridor's
    walls) or a body's footprint (a disc for round assets)."""
    zone = next((z for z in spec.zones if z.name == name), None)
    if zone is not None:
        shapes = zone.marker.collision if zone.kind == "corridor" else [zone.region]
        return [o for s in shapes if (o := _shape_outline(s, zone.pose)) is not None]
    body = next((b for b in spec.bodies if b.name == name), None)
    if body is None:
        return []
    fp = body.asset.footprint
    mid = ((fp.min_xy[0] + fp.max_xy[0]) / 2, (fp.min_xy[1] + fp.max_xy[1]) / 2)
    yaw = quat_yaw(body.pose.quaternion)
    dx, dy = rotate_xy(mid, yaw)
    center = (body.pose.position[0] + dx, body.pose.position[1] + dy)
    radius = body.asset.params.get("radius")
    if isinstance(radius, (int, float)) and not isinstance(radius, bool):
        return [Outline(center, yaw, body.pose.position[2], radius=float(radius))]
    half = ((fp.max_xy[0] - fp.min_xy[0]) / 2, (fp.max_xy[1] - fp.min_xy[1]) / 2)
    return [Outline(center, yaw, body.pose.position[2], half=half)]


def scenario_overlays(scenario: Scenario, spec: SceneSpec) -> list[Overlay]:
    """Every zone's region, and the hard and warning bands of every keep-out limit."""
    overlays: list[Overlay] = []
    for zone in spec.zones:
        for outline in reference_outlines(spec, zone.name):
            overlays.append(Overlay(zone.name, "region", outline, None, 0.0))
    layers: dict[str, int] = {}
    limits = [lim for lim in scenario.limits
              if lim.metric in METRICS and lim.reference and lim.comparison == ">="]
    # The widest band lies lowest, so narrower ones stacked on it stay visible.
    for limit in sorted(limits, key=lambda lim: -(lim.limit + lim.soft_threshold)):
        layer = layers.get(limit.reference or "", 0)
        layers[limit.reference or ""] = layer + 1
        hard, warn = max(limit.limit, 0.0), max(limit.limit, 0.0) + limit.soft_threshold
        for outline in reference_outlines(spec, limit.reference or ""):
            if hard > 0:
                overlays.append(Overlay(limit.name, "hard", outline, 0.0, hard, layer))
            if warn > hard:
                overlays.append(Overlay(limit.name, "warn", outline, hard, warn, layer))
    return overlays


def add_overlays(scene: Any, overlays: list[Overlay]) -> Any | None:
    """The overlays as one static, visual-only entity of a rendered ``scene``."""
    import sapien

    from .shapes import triangle_mesh_shape

    if not overlays:
        return None
    body = sapien.render.RenderBodyComponent()
    for overlay in overlays:
        color = COLORS[overlay.kind]
        material = sapien.render.RenderMaterial(
            base_color=list(color), emission=[*color[:3], 1.0], roughness=1.0)
        vertices, faces = overlay.mesh()
        shape = triangle_mesh_shape(vertices, faces, material)
        shape.name = f"{overlay.kind}:{overlay.name}"
        body.attach(shape)
    body.name = "safety_overlays"
    entity = sapien.Entity()
    entity.name = "safety_overlays"
    entity.add_component(body)
    scene.add_entity(entity)
    return entity


__all__ = ["COLORS", "Outline", "Overlay", "add_overlays", "reference_outlines",
           "scenario_overlays"]
