"""`python -m fsvla`: the same command line as the `fsvla` script."""

from fsvla.cli import entry

if __name__ == "__main__":
    entry()
