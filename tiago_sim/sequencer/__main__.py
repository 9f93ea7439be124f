"""`python -m tiago_sim.sequencer`: the task sequencer node."""

from tiago_sim.started_by import note_starter

note_starter()  # first: the starter's pid, before the slow imports

from tiago_sim.sequencer.startup import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main())
