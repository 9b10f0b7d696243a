"""masonry: dynamic analysis of dry-stone masonry with Non-Smooth Contact Dynamics.

From Python (a notebook, a script): ``from masonrycli import api``, then ``api.simulate("wall", amp=0.5)``
(:mod:`masonrycli.api`; ``masonry docs python``)."""

from masonrycli.source_digest import source_digest as _source_digest

__version__ = "0.1.0"

SOURCE_DIGEST = _source_digest()
"""The digest of the source this process imported, taken now (masonrycli.source_digest): what the workers'
masonry check compares."""


def __getattr__(name: str):
    # ``masonrycli.api`` after a bare ``import masonrycli`` (help(masonrycli) names it), imported only then: every
    # command, sweep worker and the compile-ahead process imports this package, and the API imports the engine
    if name == "api":
        import importlib

        return importlib.import_module("masonrycli.api")
    raise AttributeError(f"module 'masonrycli' has no attribute {name!r}")
