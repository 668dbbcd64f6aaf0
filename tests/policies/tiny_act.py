"""Save a tiny, randomly initialised LeRobot ACT policy, as ``lerobot-train`` saves one.

Run in an interpreter that has lerobot (tests/collect/lerobot_loader.py finds one)::

    python tiny_act.py OUT --state 8 --action 8 --camera front:48x64 [--action-mean ...]

It writes ``policy.save_pretrained(OUT)`` (config.json, model.safetensors) and the pre-
and post-processors with normalisation statistics (policy_preprocessor.json, ...).
Small dimensions, no pretrained backbone: it loads and acts on a CPU in a second.
"""

from __future__ import annotations

import argparse

import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.policies.factory import make_pre_post_processors


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--state", type=int, required=True)
    parser.add_argument("--action", type=int, required=True)
    parser.add_argument("--camera", action="append", default=[], help="NAME:HEIGHTxWIDTH")
    parser.add_argument("--action-mean", type=float, nargs="+", default=None,
                        help="the actions' mean (the policy acts close to it)")
    args = parser.parse_args()
    torch.manual_seed(0)
    inputs = {"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(args.state,))}
    stats = {"observation.state": {"mean": torch.zeros(args.state), "std": torch.ones(args.state)},
             "action": {"mean": torch.tensor(args.action_mean or [0.0] * args.action),
                        "std": torch.full((args.action,), 0.01)}}
    for camera in args.camera:
        name, _, size = camera.partition(":")
        height, width = (int(v) for v in size.split("x"))
        key = f"observation.images.{name}"
        inputs[key] = PolicyFeature(type=FeatureType.VISUAL, shape=(3, height, width))
        stats[key] = {"mean": torch.full((3, 1, 1), 0.5), "std": torch.full((3, 1, 1), 0.25)}
    config = ACTConfig(
        input_features=inputs,
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=(args.action,))},
        chunk_size=10, n_action_steps=5, dim_model=32, n_heads=2, dim_feedforward=64,
        n_encoder_layers=1, n_decoder_layers=1, use_vae=False,
        pretrained_backbone_weights=None, device="cpu")
    policy = ACTPolicy(config)
    policy.save_pretrained(args.out)
    preprocessor, postprocessor = make_pre_post_processors(config, dataset_stats=stats)
    preprocessor.save_pretrained(args.out)
    postprocessor.save_pretrained(args.out)


if __name__ == "__main__":
    main()
