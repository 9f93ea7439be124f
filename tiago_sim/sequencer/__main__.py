"""`python -m tiago_sim.sequencer`: the task sequencer node."""

from tiago_sim.sequencer.startup import main

if __name__ == "__main__":
    raise SystemExit(main())
