"""masonry: dynamic analysis of dry-stone masonry with Non-Smooth Contact Dynamics."""

from masonrycli.source_digest import source_digest as _source_digest

__version__ = "0.1.0"

SOURCE_DIGEST = _source_digest()
"""The digest of the source this process imported, taken now (masonrycli.source_digest): what the workers'
masonry check compares."""
