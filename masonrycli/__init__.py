"""masonry: dynamic analysis of dry-stone masonry with Non-Smooth Contact Dynamics."""

__version__ = "0.1.0"
