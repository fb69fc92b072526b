"""The bench scripts: each measures one thing, run as ``python -m studies.bench.<name>``."""
