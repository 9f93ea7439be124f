"""sila_labware package."""
