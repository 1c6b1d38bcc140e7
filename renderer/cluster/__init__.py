"""Where work runs: in this process or on Ray actors, behind one interface (executor.py).

Below the study, the checks and the batch runner (they hand it work), above core, gpu and
reference (the work it runs). Ray is an optional extra and is imported here only, lazily.
"""
