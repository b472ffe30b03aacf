"""engine.tracer.tables."""
