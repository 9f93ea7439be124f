"""tiago_sim package."""
