"""Scenario compiler: lowers checked scenario IR to scene specs, monitor specs and layout variants."""
