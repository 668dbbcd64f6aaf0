"""Rendering in SAPIEN: the Vulkan device, cameras, lights and pictures.

SAPIEN renders through Vulkan. A machine without a GPU renders on the CPU with Mesa's
lavapipe (>= 24.3); ``.ci/install-vulkan`` installs it. Without a device, a scene is
built physics-only and anything that needs pictures raises :class:`RenderUnavailable`.

Camera shaders (SAPIEN's bundled ones): ``minimal`` (fast), ``default`` (lit, better
materials; several times slower on lavapipe), ``rt`` (ray traced; slow). A light's shadow
pass roughly triples the frame time on lavapipe whatever the shader.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.scene import SceneCamera

from .shapes import sapien_pose

SHADERS = ("minimal", "default", "rt")
DEFAULT_SHADER = "minimal"

INSTALL_HINT = (
    "install a Vulkan driver: on a machine without a GPU, Mesa's software driver lavapipe "
    ">= 24.3 works (run `.ci/install-vulkan` from the fsvla repository; on Debian bookworm "
    "it installs `mesa-vulkan-drivers` from bookworm-backports)"
)


class RenderUnavailable(RuntimeError):
    """No Vulkan rendering device: the scene cannot render."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"no Vulkan rendering device ({reason}); {INSTALL_HINT}")


def create_render_system() -> Any:
    """A new SAPIEN render system; :class:`RenderUnavailable` when no device exists."""
    import sapien

    try:
        return sapien.render.RenderSystem()
    except RuntimeError as err:
        raise RenderUnavailable(str(err)) from None


def render_available() -> bool:
    """Whether SAPIEN finds a Vulkan rendering device (creates and drops a render system)."""
    try:
        create_render_system()
    except RenderUnavailable:
        return False
    return True


def check_shader(shader: str) -> str:
    if shader not in SHADERS:
        raise ValueError(f"unknown camera shader {shader!r}; shaders: {', '.join(SHADERS)}")
    return shader


def shader_dir(shader: str) -> str:
    """The folder of one of SAPIEN's bundled camera shaders."""
    import sapien

    return str(Path(sapien.__file__).resolve().parent / "vulkan_shader" / check_shader(shader))


def add_lights(scene: Any, lights: Iterable[Any], *, shadows: bool = True) -> list[Any]:
    """Add the spec's lights; returns the light components (ambient sets the scene's).
    ``shadows`` False casts no shadows whatever the lights say."""
    added = []
    for light in lights:
        if light.type == "ambient":
            scene.ambient_light = list(light.color)
        elif light.type == "directional":
            added.append(scene.add_directional_light(
                list(light.direction), list(light.color), shadow=light.shadow and shadows,
                shadow_scale=2.0, shadow_near=-4.0, shadow_far=4.0, shadow_map_size=1024))
        else:
            added.append(scene.add_point_light(list(light.position), list(light.color),
                                               shadow=light.shadow and shadows))
    return added


def make_camera(camera: SceneCamera, shader: str) -> Any:
    """A camera component with the spec's resolution and intrinsics (not yet mounted)."""
    import sapien

    component = sapien.render.RenderCameraComponent(camera.width, camera.height,
                                                    shader_dir(shader))
    component.set_fovy(camera.fovy, compute_x=True)
    component.near = camera.near
    component.far = camera.far
    component.name = camera.name
    return component


def mount_camera(scene: Any, camera: SceneCamera, shader: str, links: dict[str, Any]) -> Any:
    """Add ``camera`` to ``scene``: on its own entity (``parent`` "world") or on the arm's
    ee link entity (``links`` maps arm names to their ee link components)."""
    import sapien

    component = make_camera(camera, shader)
    if camera.parent == "world":
        entity = sapien.Entity()
        entity.name = f"camera_{camera.name}"
        entity.add_component(component)
        entity.pose = sapien_pose(camera.pose)
        scene.add_entity(entity)
    else:
        if camera.parent not in links:
            raise KeyError(f"camera {camera.name!r} rides on arm {camera.parent!r}, "
                           f"which the embodiment lacks (arms: {', '.join(links)})")
        links[camera.parent].entity.add_component(component)
        component.local_pose = sapien_pose(camera.pose)
    return component


def picture_rgb(camera: Any) -> NDArray[np.uint8]:
    """The camera's last picture as HWC uint8 RGB (call ``take_picture`` first)."""
    rgba = np.asarray(camera.get_picture("Color"))
    if rgba.dtype != np.uint8:
        rgba = np.clip(rgba * 255.0 + 0.5, 0.0, 255.0).astype(np.uint8)
    return np.ascontiguousarray(rgba[..., :3])


__all__ = [
    "DEFAULT_SHADER",
    "INSTALL_HINT",
    "SHADERS",
    "RenderUnavailable",
    "add_lights",
    "check_shader",
    "create_render_system",
    "make_camera",
    "mount_camera",
    "picture_rgb",
    "render_available",
    "shader_dir",
]
