"""The SAPIEN back-end of the fsvla runtime: it implements the protocols of ``fsvla.world``
through which the monitor, the experts and the visual variation read and change a scene.

Importing this package does not import SAPIEN; the modules that need it import it
inside their functions, so ``fsvla check`` and spec-only code stay cheap.

- :func:`build` (in ``fsvla.sim.builder``): a SceneSpec to a SAPIEN scene, a :class:`BuiltScene`.
- ``fsvla.sim.render``: the Vulkan device, cameras, lights (:class:`RenderUnavailable`).
- ``fsvla.sim.overlays`` and ``fsvla.sim.preview``: safety overlays, ``fsvla preview``.
- ``fsvla.sim.robot``: embodiments as PD-driven articulations (:func:`load_robot`);
  ``fsvla.sim.kinematics``: an arm's FK and IK (``fsvla.world.ArmModel``).
- ``fsvla.sim.probe``: the monitor's reader of contacts, poses and joints
  (``fsvla.world.StepProbe``); ``fsvla.sim.appearance``: a rendering scene's look, for
  the visual variation (``fsvla.world.SceneAppearance``).
"""

from __future__ import annotations

from .builder import BuiltScene, build
from .render import RenderUnavailable, render_available

__all__ = ["BuiltScene", "RenderUnavailable", "build", "render_available"]
