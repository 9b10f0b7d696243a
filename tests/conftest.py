import os

os.environ.setdefault("RERUN_ANALYTICS", "0")
