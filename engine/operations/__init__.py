"""engine.operations."""
