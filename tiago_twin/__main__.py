"""`python -m tiago_twin`: the simulated robot with its skills (see tiago_twin.startup)."""

from tiago_twin.startup import main

if __name__ == "__main__":
    raise SystemExit(main())
