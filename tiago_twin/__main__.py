"""`python -m tiago_twin`: the simulated robot with its skills (see tiago_twin.startup)."""

from tiago_sim.started_by import note_starter

note_starter()  # first: the starter's pid, before the slow imports

from tiago_twin.startup import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main())
