"""Navigation: the lab as an occupancy map, and what plans and localises on it."""
