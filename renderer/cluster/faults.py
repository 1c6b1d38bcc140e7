"""What a lost batch costs: how often one is tried, and the error when that is not enough.

Its own module so that executor.py (which opens a RayExecutor) and ray_executor.py (which
retries batches) share it without importing each other.
"""

from renderer.errors import SystemFault

MAX_ATTEMPTS = 3            # a batch failing this many times fails the job (BatchFailed)


class BatchFailed(SystemFault):
    """A batch failed MAX_ATTEMPTS times, its worker's process lost each time (the last
    error chained): the system failed, not the user, so one line and exit status 1."""
