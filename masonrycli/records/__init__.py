"""Ground-motion records: files read into support motions, their units checked, their intensity measured.

- ``read``: ``read_record`` and the formats it recognises; ``text``: the numbers of a record file's text.
- ``esm``, ``knet``: the ESM / ITACA and K-NET / KiK-net formats (PEER ``.AT2`` lives in ``read``).
- ``units``: what a file's header says about its units; ``velocity``: the velocity history a record defines.
- ``motion``: ``Record``, the ``record`` kind of support motion; ``intensity``: intensity measures as applied.
"""
