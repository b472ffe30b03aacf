"""The labels panel and its parts (module map in :mod:`widgets.labels.panel`)."""
from widgets.labels.panel import LabelsPanel  # noqa: F401
