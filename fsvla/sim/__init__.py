"""The SAPIEN back-end of the fsvla runtime.

Importing this package does not import SAPIEN; the modules that need it import it
inside their functions, so ``fsvla check`` and spec-only code stay cheap.
"""
