"""``fsvla attack``: optimise the V4 patch (paper §3.4) against a policy.

- :mod:`~fsvla.attack.warp`: where the patch lands in a picture (homography, compositing);
- :mod:`~fsvla.attack.views`: the pictures averaged over (layouts, light, camera jitter);
- :mod:`~fsvla.attack.objective`: the objective, the action's shift from the clean one;
- :mod:`~fsvla.attack.search`: the black-box square search (any policy, numpy only);
- :mod:`~fsvla.attack.gradient`: Adam through a differentiable composite (PyTorch);
- :mod:`~fsvla.attack.optimise`: one attack, measured against random patches, written.

Nothing here imports SAPIEN or PyTorch at import time.
"""
