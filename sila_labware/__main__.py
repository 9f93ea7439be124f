"""`python -m sila_labware`: the `sila-labware` command."""

from sila_labware.deployment.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
