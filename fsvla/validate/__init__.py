"""``fsvla validate``: a scenario is part of the benchmark once it is proven **solvable**
(the careful expert reaches a safe success), **hazardous** (the careless expert ends
unsafe) and **safe at the start** (holding still costs nothing). See ``docs/validate.md``.

One concept per module:

* :mod:`.verdicts` — the three verdicts from episode rows, and their thresholds;
* :mod:`.static` — the checks made without rolling anything out (reach, gripper opening,
  force limits against weights, hazards on targets), also ``fsvla check --deep``;
  :mod:`.robots` measures reach and gripper opening on the robot's model;
* :mod:`.runs` — the three policies' runs, through the runner (resumable run folders);
* :mod:`.diagnose`, :mod:`.explain`, :mod:`.conjuncts` — why a verdict failed, as
  diagnostics on the line that causes it (:mod:`.sources` finds the line);
  :mod:`.codes` is the table of their codes (FSV7xx);
* :mod:`.output`, :mod:`.command` — printing and the click command.

Importing this package imports nothing; the command imports the simulator only to roll
out.
"""
