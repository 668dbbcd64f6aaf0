"""The diagnostic codes of ``fsvla validate`` and ``fsvla check --deep`` (FSV7xx).

One table, the catalogue ``docs/validate.md`` documents (its test walks this table):
FSV70x are the static findings (no rollout), FSV71x explain a scenario that is not
solvable, FSV72x one that does not start safe, FSV73x one that is not hazardous.
"""

from __future__ import annotations

# --- static (warnings: predictions from the layout, made without rolling anything out)
REACH = "FSV701"  # a task object, or the part it moves, beyond every arm's reach
GRIPPER = "FSV702"  # no part of an object the task grasps fits the gripper
WEIGHT = "FSV703"  # a force limit below what lifting a task object needs
HAZARD_ON_TARGET = "FSV704"  # a hazard's keep-out covers the whole target

# --- solvable (errors: the careful expert's episodes say so)
NEVER_HELD = "FSV710"  # a conjunct of `success` never held
NEVER_TOGETHER = "FSV711"  # every conjunct held, never all together for the hold time
CAREFUL_VIOLATION = "FSV712"  # the careful expert crossed a hard limit
CAREFUL_FAULT = "FSV713"  # the careful expert's episode faulted

# --- starts safe (errors: the hold-still episodes say so)
START_WARNING = "FSV720"  # a channel in its warning band at the start
HOLD_VIOLATION = "FSV721"  # holding still crosses a hard limit
HOLD_EXPOSURE = "FSV722"  # holding still enters a warning band later on
HOLD_FAULT = "FSV723"  # the hold-still episode faulted
DONE_AT_REST = "FSV724"  # holding still, `success` holds: the task is done without acting

# --- hazardous (errors: the careless expert's episodes say so)
NOT_HAZARDOUS = "FSV730"  # the careless expert ends unsafe too rarely

CODES: dict[str, str] = {
    REACH: ("a task object, or the knob or handle of the part the task moves, is beyond the "
            "reach of every arm (of each arm, for a two-arm lift)"),
    GRIPPER: ("an object the task grasps has no part the gripper closes on: wider, everywhere, "
              "than it opens, or thinner than its shut fingers squeeze"),
    WEIGHT: "a contact-force limit is below what lifting a task object needs",
    HAZARD_ON_TARGET: "a hazard's keep-out distance covers every place on the task's target",
    NEVER_HELD: "a conjunct of `success` never held in a failed careful-expert episode",
    NEVER_TOGETHER: "every conjunct of `success` held, but never all together for its hold time",
    CAREFUL_VIOLATION: "the careful expert crossed a hard limit",
    CAREFUL_FAULT: "a careful-expert episode faulted (policy or simulator error)",
    START_WARNING: "holding still, a channel is in its warning band at the first step",
    HOLD_VIOLATION: "holding still crosses a hard limit",
    HOLD_EXPOSURE: "holding still, a channel enters its warning band after the first step",
    HOLD_FAULT: "a hold-still episode faulted",
    DONE_AT_REST: "holding still, `success` holds: nothing has to be done to succeed",
    NOT_HAZARDOUS: "the careless expert ends unsafe in too few episodes",
}

__all__ = ["CAREFUL_FAULT", "CAREFUL_VIOLATION", "CODES", "DONE_AT_REST", "GRIPPER", "HAZARD_ON_TARGET",
           "HOLD_EXPOSURE", "HOLD_FAULT", "HOLD_VIOLATION", "NEVER_HELD", "NEVER_TOGETHER",
           "NOT_HAZARDOUS", "REACH", "START_WARNING", "WEIGHT"]
