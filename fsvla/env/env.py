"""The fsvla gymnasium environment: one scenario layout, a policy's actions, the monitor.

``FsvlaEnv`` compiles a scenario's layout variant (level, seed) to a SceneSpec and a
MonitorSpec, builds the SAPIEN scene (physics only unless images are asked for), and
then, at every ``step``: validates the action (:mod:`fsvla.env.actions`), sets the drive
targets, runs the physics substeps of one control step while the safety monitor samples
each substep, and returns the observation, a sparse reward (1 when the success condition
has held for its hold time, else 0), ``terminated`` on success (or on a hard violation
when ``terminate_on_violation``), ``truncated`` at the scenario's horizon, and the
monitor's report in ``info``. A hard violation does not end the episode by default: the
paper keeps exposure running so CC and RET measure the whole episode.

The benchmark coordinates are fixed at construction: the layout by ``level`` and
``seed`` (L0–L2), the instruction by ``language`` (W0–W4) and the pictures by ``vision``
(V0–V4), both drawn with the same ``seed`` (``fsvla.variation``) unless ``language_seed`` /
``vision_seed`` are given; ``vary()`` changes W and V for the next episodes. Vision levels change
only rendered observations, so they need ``obs_mode="rgb"``; ``patch`` names a PNG file that
V4's patches show (else each shows its seeded pattern). ``cameras``, ``resolution`` and
``shader`` choose what is rendered; an observation's pictures are rendered when they are
first read (:mod:`fsvla.env.frames`), not at every step. ``reset(seed=...)`` seeds nothing else (the simulation is deterministic);
a reset after an episode rebuilds the SAPIEN scene, whose contact caches no state reset
clears, so the same seed and actions give the identical trace in any episode.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import gymnasium
import numpy as np

from fsvla.compiler.monitor import MonitorSpec, lower_monitor
from fsvla.compiler.scene import Level, SceneCamera, SceneSpec
from fsvla.compiler.variants import generate_variant
from fsvla.dsl.models import Scenario
from fsvla.embodiments import load_embodiment
from fsvla.library import ScenarioRef, load_scenario
from fsvla.monitor import SafetyMonitor
from fsvla.monitor.start import start_error
from fsvla.sim.builder import BuiltScene, build
from fsvla.sim.cameras import camera_selection, parse_resolution
from fsvla.sim.kinematics import ArmKinematics
from fsvla.sim.render import DEFAULT_SHADER, check_shader
from fsvla.sim.robot import LoadedArm
from fsvla.variation.apply import VisionApplier
from fsvla.variation.language import Instruction, instruction_for
from fsvla.variation.vision import VisionPerturbation, perturbation_for

from .actions import ActionCodec, ArmCommand, ArmLayout, ControlMode, joint_targets, tcp_target
from .frames import LazyImages, StaleFrameError
from .observations import assemble, check_instruction, observation_space, proprioception
from .recording import EpisodeRecorder

OBS_MODES = ("state", "rgb")


@dataclass(frozen=True)
class EnvConfig:
    """Everything that fixes an environment instance, echoed into every trace."""

    scenario: str
    level: Level
    seed: int
    language: str
    vision: str
    embodiment: str
    obs_mode: str
    control_mode: str
    terminate_on_violation: bool
    monitor: bool
    cameras: tuple[str, ...] = ()  # the cameras rendered (rgb observations, render())
    resolution: tuple[int, int] | None = None  # (width, height) of each; None: the spec's
    shader: str = DEFAULT_SHADER


class FsvlaEnv(gymnasium.Env):
    """A gymnasium environment for one scenario at one layout (level, seed)."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 20}
    built: BuiltScene
    monitor: SafetyMonitor | None
    _vision: VisionApplier | None

    def __init__(
        self,
        scenario: ScenarioRef,
        level: Level = "L0",
        seed: int = 0,
        embodiment: str | None = None,
        obs_mode: str = "state",
        control_mode: str = "joint_pos",
        *,
        language: str = "W0",
        vision: str = "V0",
        instruction: str | None = None,
        terminate_on_violation: bool = False,
        monitor: bool = True,
        render_mode: str | None = None,
        language_seed: int | None = None,
        vision_seed: int | None = None,
        cameras: Sequence[str] | None = None,
        resolution: tuple[int, int] | str | None = None,
        shader: str = DEFAULT_SHADER,
        lazy_images: bool = False,
        patch: str | None = None,
    ) -> None:
        if obs_mode not in OBS_MODES:
            raise ValueError(f"obs_mode must be one of {', '.join(OBS_MODES)}, got {obs_mode!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        source = load_scenario(scenario)
        spec = load_embodiment(embodiment) if embodiment is not None else None
        variant = generate_variant(source, level=level, seed=seed, embodiment=spec)
        self.scenario: Scenario = variant.scenario
        self.scene_spec: SceneSpec = variant.scene
        self.monitor_spec: MonitorSpec = lower_monitor(variant.scenario, variant.scene)
        size = parse_resolution(resolution) if resolution is not None else None
        #: The scene as rendered: the layout's, with the chosen cameras at their resolution.
        self.render_spec: SceneSpec = self.scene_spec.model_copy(update={
            "cameras": camera_selection(self.scene_spec.cameras, cameras, size)})
        self.config = EnvConfig(
            scenario=source.name, level=level, seed=seed, language=language, vision=vision,
            embodiment=self.scene_spec.embodiment.name, obs_mode=obs_mode,
            control_mode=ControlMode(control_mode).value,
            terminate_on_violation=terminate_on_violation, monitor=monitor,
            cameras=tuple(c.name for c in self.render_spec.cameras), resolution=size,
            shader=check_shader(shader))
        self._lazy_images = lazy_images
        self._patch = patch  # a PNG file: the V4 patches' pixels (else their seeded pattern)
        self._epoch = 0  # counts steps and resets: which scene state a picture shows
        self._frame: tuple[int, dict[str, np.ndarray]] | None = None  # (epoch, raw views)
        #: Render passes so far (each renders every camera once): the cost of the pictures.
        self.frames_rendered = 0
        self._source = source
        wants_images = obs_mode == "rgb" or render_mode == "rgb_array"
        if vision != "V0" and not wants_images:
            raise ValueError(f"vision level {vision} changes only pictures; it needs "
                             "obs_mode='rgb' (or render_mode='rgb_array')")
        self._render = wants_images
        self._build_scene()
        self.vary(language, vision, language_seed=language_seed, vision_seed=vision_seed,
                  instruction=instruction)

        arms = list(self.built.robot.arms.values())
        layouts = [_layout(arm) for arm in arms]
        self.codec = ActionCodec(layouts, control_mode)
        self._bind_kinematics()
        self.action_space = self.codec.space()
        self.observation_space = observation_space(
            [v for layout in layouts for v in _finite(layout.lower, -np.pi)],
            [v for layout in layouts for v in _finite(layout.upper, np.pi)],
            len(arms), self.cameras, with_images=obs_mode == "rgb")
        physics = self.scene_spec.physics
        self.substeps = physics.substeps
        self.control_dt = physics.control_dt
        self.max_steps = max(1, round(self.scenario.horizon / self.control_dt))
        self.recorder = EpisodeRecorder(self.monitor_spec, self.codec.labels)
        self._t = 0

    # -------------------------------------------------------------- gymnasium API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        if self._stepped:
            # PhysX keeps contact and solver caches that no state reset clears, so an
            # episode after contact would depend on the one before it: rebuild instead.
            self._build_scene()
            if self._vision is not None:
                self._vision.apply(self.vision)
            self._bind_kinematics()
        self.built.reset()
        if self.monitor is not None:
            self.monitor.reset()
            self._check_start()
        self.recorder.start()
        self._t = 0
        self._epoch += 1
        info = {"step": 0, "max_steps": self.max_steps, "instruction": self.instruction}
        return self._observe(), info

    def step(self, action: Any):
        commands = self.codec.decode(action)
        self._stepped = True
        self._epoch += 1  # the pictures of the last observation can no longer be rendered
        ik_errors = self._apply(commands)
        monitor = self.monitor
        ramps, substep_dt = self._ramps, self.control_dt / self.substeps
        for substep in range(self.substeps):
            for arm, command, layout, start in ramps:  # joint_vel: the target moves at v
                arm.set_joint_targets(joint_targets(command, layout, start,
                                                    (substep + 1) * substep_dt))
            self.built.step(1)
            if monitor is not None:
                monitor.record_substep()
        self._t += 1
        info: dict[str, Any] = {"step": self._t}
        success = violation = False
        if self.monitor is not None:
            report = self.monitor.end_step()
            success, violation = report.success, report.any_violation
            info.update(report.info())
            self.recorder.add(np.asarray(action, dtype=np.float64), report)
        if ik_errors:
            info["ik_error"] = ik_errors
        terminated = success or (violation and self.config.terminate_on_violation)
        truncated = not terminated and self._t >= self.max_steps
        return self._observe(), float(success), terminated, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        views = self._views()
        return np.concatenate(list(views.values()), axis=1) if views else None

    def close(self) -> None:
        self.built = None  # type: ignore[assignment]  # drop the SAPIEN scene

    def vary(self, language: str, vision: str, *, language_seed: int | None = None,
             vision_seed: int | None = None, instruction: str | None = None) -> None:
        """Give the next episodes the instruction of ``language`` (W) and the pictures of
        ``vision`` (V), drawn with their seeds (default: the layout seed) from the source
        scenario (its digest seeds them); the scene is not rebuilt. Call before ``reset``."""
        if vision != "V0" and self._vision is None:
            raise ValueError(f"vision level {vision} changes only pictures; it needs "
                             "obs_mode='rgb' (or render_mode='rgb_array')")
        seed = self.config.seed
        self.language: Instruction = instruction_for(  # type: ignore[arg-type]
            self._source, language, seed if language_seed is None else language_seed)
        self.vision: VisionPerturbation = perturbation_for(  # type: ignore[arg-type]
            self._source, vision, seed if vision_seed is None else vision_seed, self._patch)
        self.instruction = check_instruction(instruction if instruction is not None
                                             else self.language.text)
        if self._vision is not None:
            self._vision.apply(self.vision)
        self.config = replace(self.config, language=language, vision=vision)

    @property
    def cameras(self) -> tuple[SceneCamera, ...]:
        """The cameras rendered, as built (name, mount, resolution); empty without
        rendering."""
        return tuple(c for c in self.render_spec.cameras if c.name in self.built.cameras)

    # -------------------------------------------------------------- traces
    def episode_record(self):
        """The episode so far: per-step margins, costs, states, actions (see recording)."""
        return self.recorder.record()

    # -------------------------------------------------------------- internals
    def _build_scene(self) -> None:
        """A fresh SAPIEN scene of the layout, with its monitor and visual variation."""
        self.built = build(self.render_spec, render=self._render, shader=self.config.shader)
        self.monitor = SafetyMonitor(self.monitor_spec, self.built) if self.config.monitor else None
        self._vision = (VisionApplier(self.built.appearance(), self.render_spec)
                        if self.built.renders else None)
        self._stepped = False

    def _check_start(self) -> None:
        """A layout must start outside every warning band (docs/variants.md); the compiler
        checks what the layout decides, this the robot at its home pose: FSV604 otherwise."""
        exposures = self.monitor.evaluator.start_exposures()  # type: ignore[union-attr]
        error = start_error(self.scenario, self.config.level, self.config.seed, exposures)
        if error is not None:
            raise error

    def _bind_kinematics(self) -> None:
        arms = self.built.robot.arms.values()
        self._kinematics = ({arm.name: ArmKinematics(arm) for arm in arms}
                            if not self.codec.mode.in_joint_space else {})

    def _apply(self, commands: tuple[ArmCommand, ...]) -> dict[str, float]:
        """Set drive targets (a joint_vel command's position targets are set at every
        substep, from ``self._ramps``); returns the IK position error (m) of arms that
        missed."""
        robot = self.built.robot
        missed: dict[str, float] = {}
        self._ramps: list[tuple[LoadedArm, ArmCommand, ArmLayout, np.ndarray]] = []
        for command, layout in zip(commands, self.codec.arms):
            arm = robot.arm(command.arm)
            if command.joint_velocity is not None:
                arm.set_joint_velocity_targets(command.joint_velocity)
                self._ramps.append((arm, command, layout, arm.qpos()))
            elif command.in_joint_space:
                arm.set_joint_targets(joint_targets(command, layout, arm.qpos()))
            else:
                pose = arm.tcp_pose()
                position, quaternion = tcp_target(command, pose.p, pose.q)
                solution = self._kinematics[command.arm].inverse(
                    tuple(position), tuple(quaternion), seed=arm.qpos(), restarts=2)
                arm.set_joint_targets(solution.qpos)
                if not solution.ok():
                    missed[command.arm] = solution.position_error
            arm.set_gripper_opening(command.gripper)
        return missed

    def _observe(self) -> dict[str, Any]:
        images = None
        if self.config.obs_mode == "rgb":
            epoch = self._epoch
            images = LazyImages(self.built.cameras, lambda: self._pictures(epoch))
            if not self._lazy_images:
                images = images.copy()
        return assemble(proprioception(self.built.robot), self.instruction, images)

    def _pictures(self, epoch: int) -> dict[str, np.ndarray]:
        """The observation pictures of ``epoch``, while the scene is still there."""
        if epoch != self._epoch:
            raise StaleFrameError(
                "the images of this observation were not read before the environment "
                "stepped or reset, and can no longer be rendered: read obs['images'] before "
                "the next step, or make the environment with lazy_images=False")
        return self._views()

    def _views(self) -> dict[str, np.ndarray]:
        """Every camera's picture of the scene now, rendered once per step."""
        if self._frame is None or self._frame[0] != self._epoch:
            self._frame = (self._epoch, self.built.render_views())
            self.frames_rendered += 1
        return self._frame[1]


def _finite(values: tuple[float, ...], bound: float) -> list[float]:
    """Joint limits with an unlimited (continuous) joint bounded by ``bound`` times 100."""
    return [v if np.isfinite(v) else 100.0 * bound for v in values]


def _layout(arm: LoadedArm) -> ArmLayout:
    joints = arm.articulation.active_joints
    limits = [joints[i].limit[0] for i in arm.joint_indices]
    return ArmLayout(arm.name, tuple(arm.spec.joints),
                     tuple(float(lo) for lo, _ in limits), tuple(float(hi) for _, hi in limits))


__all__ = ["OBS_MODES", "EnvConfig", "FsvlaEnv"]
