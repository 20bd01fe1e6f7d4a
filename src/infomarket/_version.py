"""The package version, written only here.

pyproject.toml reads it (``[tool.hatch.version]``); the package root re-exports it as
``infomarket.__version__``, and the compiled-kernel cache, stores, reports and the command line import it
from this module, so none of them has to import the package root (which imports them) to learn it.
"""
__version__ = "0.1.0"
