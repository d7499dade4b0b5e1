"""bracket."""
