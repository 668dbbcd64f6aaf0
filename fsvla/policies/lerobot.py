"""A LeRobot pretrained policy (``--policy lerobot:PATH``): ACT, Diffusion Policy, SmolVLA,
pi0, ... from the folder ``policy.save_pretrained()`` writes (``config.json`` and
``model.safetensors``, with ``policy_preprocessor.json`` and ``policy_postprocessor.json``
where ``lerobot-train`` saved its normalisation).

The checkpoint declares its inputs; each is fed from fsvla's observation:

=============================  ==============================================================
``observation.state``          joint positions, then each gripper's opening (what
                               ``fsvla collect`` records under that name)
``observation.tcp_pose``       each arm's tool pose ``[x, y, z, qw, qx, qy, qz]``
``observation.images.<name>``  fsvla's camera ``<name>``, resized to the declared size,
                               CHW float in [0, 1] (needs ``--obs-mode rgb``)
task text                      the episode's instruction, as ``task``
=============================  ==============================================================

Its ``action`` output is taken as an action of the run's control mode (``joint_pos``
unless ``--control-mode`` says otherwise), so its width must be that mode's. Chunking is
the policy's own: ACT, SmolVLA, pi0 and pi0.5 (one observation step, no temporal
ensembling) are asked for a chunk and its first ``n_action_steps`` actions run; other
policies (Diffusion Policy's observation history, ACT's temporal ensembling) are asked
through their ``select_action`` at every step, as LeRobot's own evaluation does.

LeRobot and PyTorch are imported only here, when such a policy is loaded: they must be
installed in fsvla's environment (``pip install lerobot``). Inference runs on the GPU
when PyTorch sees one, else on the CPU.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from .base import EpisodeInfo
from .registry import PolicyLoadError

PREFIX = "lerobot:"
#: Policies whose ``select_action`` only queues the first ``n_action_steps`` of a predicted
#: chunk (when they see one observation step and do no temporal ensembling).
CHUNKED = frozenset({"act", "smolvla", "pi0", "pi05"})
STATE = "observation.state"
TCP_POSE = "observation.tcp_pose"
IMAGES = "observation.images."
ACTION = "action"
INSTALL = "pip install lerobot (in the environment fsvla runs in; it brings PyTorch)"


class LeRobotMismatch(ValueError):
    """A checkpoint whose declared features this episode cannot feed or take."""


class FeatureMap(BaseModel):
    """Where each declared input of a checkpoint comes from, for one episode."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    state: str | None = None  # the policy's key fed with joints + grippers
    tcp_pose: str | None = None
    cameras: dict[str, str] = {}  # the policy's image key -> fsvla camera
    image_sizes: dict[str, tuple[int, int]] = {}  # the policy's image key -> (height, width)
    action_size: int


def check_inputs(inputs: Mapping[str, Sequence[int]]) -> None:
    """Refuse (at load time) declared inputs fsvla never provides."""
    unknown = [k for k in inputs if k not in (STATE, TCP_POSE) and not k.startswith(IMAGES)]
    if unknown:
        raise PolicyLoadError(
            f"the checkpoint reads {', '.join(unknown)}, which fsvla does not provide; fsvla "
            f"feeds {STATE} (joints, then grippers), {TCP_POSE} and {IMAGES}<camera>")


def map_features(inputs: Mapping[str, Sequence[int]], action_shape: Sequence[int],
                 episode: EpisodeInfo) -> FeatureMap:
    """How ``episode``'s observations feed the declared ``inputs`` (key -> shape), and the
    declared action's width; raises :class:`LeRobotMismatch` saying what to change."""
    layout = episode.observation.state_layout
    state_labels = [*layout.get("qpos", ()), *layout.get("gripper", ())]
    tcp_labels = layout.get("tcp_pose", ())
    cameras = {c.name: c for c in episode.observation.cameras}
    embodiment = episode.key.embodiment
    fields: dict[str, Any] = {"cameras": {}, "image_sizes": {}}
    for key, shape in inputs.items():
        size = int(np.prod(shape))
        if key in (STATE, TCP_POSE):
            labels = state_labels if key == STATE else tcp_labels
            if size != len(labels):
                raise LeRobotMismatch(
                    f"the checkpoint's {key} has {size} values; on {embodiment} fsvla's has "
                    f"{len(labels)} ({', '.join(labels)}): run it with --embodiment of the "
                    "robot it was trained on")
            fields["state" if key == STATE else "tcp_pose"] = key
            continue
        camera = key.removeprefix(IMAGES)
        if not cameras:
            raise LeRobotMismatch(f"the checkpoint reads camera images ({key}); run with "
                                  "--obs-mode rgb")
        if camera not in cameras:
            raise LeRobotMismatch(
                f"the checkpoint reads {key}, and {embodiment} here has no camera {camera!r} "
                f"(it has {', '.join(sorted(cameras))}); name the cameras it was trained "
                "with, as fsvla collect records them")
        if len(shape) != 3 or shape[0] != 3:
            raise LeRobotMismatch(f"the checkpoint's {key} has shape {tuple(shape)}; fsvla "
                                  "feeds RGB images, shape (3, height, width)")
        fields["cameras"][key] = camera
        fields["image_sizes"][key] = (int(shape[1]), int(shape[2]))
    width = len(episode.action.labels)
    action = int(np.prod(action_shape))
    if action != width:
        raise LeRobotMismatch(
            f"the checkpoint's action has {action} values; the episode's "
            f"{episode.action.control_mode} action on {embodiment} has {width} "
            f"({', '.join(episode.action.labels)}): run with the --control-mode and "
            "--embodiment it was trained with")
    return FeatureMap(action_size=width, **fields)


def observation_arrays(observation: Mapping[str, Any], features: FeatureMap
                       ) -> dict[str, NDArray[Any]]:
    """The declared inputs as arrays with a batch axis of one: vectors float32, images
    ``(1, 3, H, W)`` float32 in [0, 1] at the camera's own size."""
    agent = observation["agent"]
    out: dict[str, NDArray[Any]] = {}
    if features.state is not None:
        state = np.concatenate([agent["qpos"], agent["gripper"]])
        out[features.state] = np.asarray(state, dtype=np.float32)[None]
    if features.tcp_pose is not None:
        out[features.tcp_pose] = np.asarray(agent["tcp_pose"], dtype=np.float32)[None]
    for key, camera in features.cameras.items():
        pixels = np.asarray(observation["images"][camera], dtype=np.float32) / 255.0
        out[key] = np.ascontiguousarray(np.transpose(pixels, (2, 0, 1))[None])
    return out


class LeRobotPolicy:
    """A LeRobot checkpoint folder as an fsvla policy (see the module doc)."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self.name = f"{PREFIX}{path}"
        _check_folder(self.path)
        try:
            import torch
            from lerobot.configs.policies import PreTrainedConfig
            from lerobot.policies.factory import get_policy_class, make_pre_post_processors
        except ImportError as err:
            raise PolicyLoadError(f"--policy {self.name}: LeRobot is not installed here "
                                  f"({err}); {INSTALL}") from None
        self._torch = torch
        try:
            config = PreTrainedConfig.from_pretrained(str(self.path))
        except Exception as err:  # noqa: BLE001 - draccus/json: a config.json LeRobot cannot read
            raise PolicyLoadError(f"--policy {self.name}: {self.path / 'config.json'} is not a "
                                  f"LeRobot policy config ({type(err).__name__}: {err})") from None
        self.inputs = {k: tuple(f.shape) for k, f in config.input_features.items()}
        outputs = {k: tuple(f.shape) for k, f in config.output_features.items()}
        try:
            check_inputs(self.inputs)
        except PolicyLoadError as err:
            raise PolicyLoadError(f"--policy {self.name}: {err}") from None
        if ACTION not in outputs:
            raise PolicyLoadError(f"--policy {self.name}: the checkpoint declares no `action` "
                                  f"output (it has {', '.join(outputs) or 'none'})")
        self.action_shape = outputs[ACTION]
        self.device = "cuda" if torch.cuda.is_available() else "cpu"
        config.device = self.device
        try:
            self.policy = get_policy_class(config.type).from_pretrained(str(self.path),
                                                                        config=config)
            self.policy.eval()
            self.preprocess, self.postprocess = self._processors(config, make_pre_post_processors)
        except Exception as err:  # noqa: BLE001 - weights that do not fit the config, a bad file
            raise PolicyLoadError(f"--policy {self.name}: LeRobot could not load the "
                                  f"checkpoint: {type(err).__name__}: {err}") from None
        self.config = config
        self.chunked = (config.type in CHUNKED and int(getattr(config, "n_obs_steps", 1)) == 1
                        and getattr(config, "temporal_ensemble_coeff", None) is None)
        self.n_action_steps = int(getattr(config, "n_action_steps", 1))
        self._features: FeatureMap | None = None
        self._instruction = ""

    def _processors(self, config: Any, make: Any) -> tuple[Any, Any]:
        """The checkpoint's saved pre/post-processors (normalisation), or LeRobot's
        defaults for the policy type where none were saved."""
        if (self.path / "policy_preprocessor.json").exists():
            return make(config, pretrained_path=str(self.path),
                        preprocessor_overrides={"device_processor": {"device": self.device}})
        return make(config)

    def reset(self, episode: EpisodeInfo) -> None:
        try:
            self._features = map_features(self.inputs, self.action_shape, episode)
        except LeRobotMismatch as err:
            raise LeRobotMismatch(f"--policy {self.name}: {err}") from None
        self._instruction = episode.instruction
        self.policy.reset()
        for pipeline in (self.preprocess, self.postprocess):
            pipeline.reset()

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        torch = self._torch
        features = self._features
        assert features is not None, "reset(episode) comes first"
        batch: dict[str, Any] = {}
        for key, array in observation_arrays(observation, features).items():
            tensor = torch.from_numpy(array)
            if key in features.image_sizes and tuple(tensor.shape[-2:]) != features.image_sizes[key]:
                tensor = torch.nn.functional.interpolate(
                    tensor, size=features.image_sizes[key], mode="bilinear", antialias=True,
                    align_corners=False)
            batch[key] = tensor
        batch["task"] = [self._instruction]
        with torch.inference_mode():
            batch = self.preprocess(batch)
            if self.chunked:
                actions = self.policy.predict_action_chunk(batch)[:, :self.n_action_steps]
            else:
                actions = self.policy.select_action(batch)
            actions = self.postprocess(actions)
        return actions.reshape(-1, features.action_size).detach().cpu().numpy().astype(np.float64)


def _check_folder(path: Path) -> None:
    spec = f"{PREFIX}{path}"
    if not path.is_dir():
        raise PolicyLoadError(f"--policy {spec}: no such folder; give the folder a LeRobot "
                              "policy was saved to (config.json and model.safetensors)")
    missing = [n for n in ("config.json", "model.safetensors") if not (path / n).is_file()]
    if missing:
        raise PolicyLoadError(f"--policy {spec}: not a LeRobot policy folder (no "
                              f"{' or '.join(missing)}); give the folder policy.save_pretrained() "
                              "wrote, e.g. a checkpoint's pretrained_model/")


__all__ = ["CHUNKED", "FeatureMap", "LeRobotMismatch", "LeRobotPolicy", "check_inputs",
           "map_features", "observation_arrays"]
