"""`python -m sila_labware`: the `sila-labware` command (see `sila_labware.cli`)."""

from sila_labware.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
