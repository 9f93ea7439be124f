"""A simulated lab for other projects' tests: the pytest plugin and what it stands on."""
