"""The fixed settings of `renderer report`: sizes, targets, the CSV's columns and the textbook
convergence rates, read by the sweep (report.py) and by its output (report_output.py)."""

DEFAULT_SIZE = (160, 120)
QUICK_SIZE = (64, 48)
QUICK_SCENES = ("flat_shading", "gouraud_vs_phong")
# The errors the "cheapest setting" must reach: about 2.6/255, where one sample often does,
# and about 0.8/255, where the patterns part ways.
TARGETS_RMSE = (0.01, 0.003)
MISMATCH_LEVELS = 2                  # of 255: a pixel further off than this is mismatched
BASE_SAMPLES = 4                     # regular grid for the knobs other than antialiasing
CSV_COLUMNS = ("scene", "knob", "setting", "backend", "pattern", "samples", "runs", "median_ms",
               "rmse", "max_abs", "psnr", "flip_mean", "mismatched_fraction")
TEXTBOOK_SLOPES = {                  # RMSE against N (Mitchell 1996; docs/report)
    "regular": ("N^-0.5 at worst", "coverage steps of 1/k on a k x k grid: the worst case, "
                "edges along the grid; other edges do better, but the grid aliases"),
    "random": ("N^-0.5", "independent samples: the Monte Carlo rate"),
    "jittered": ("N^-0.75 at edges", "one sample per stratum"),
    "poisson": ("about N^-0.75", "between random and jittered, close to jittered"),
}

# The ray tracer's report (renderer/study/ray_report.py, ray_report_output.py).
RAY_DEFAULT_SIZE = (160, 120)
RAY_QUICK_SIZE = (64, 48)
RAY_QUICK_SCENES = ("classic",)
RAY_MAX_SIZE = (320, 240)            # its ground truth traces 1024 rays per pixel in float64
RAY_BASE_SAMPLES = 16                # jittered, for the knobs other than antialiasing
RAY_CSV_COLUMNS = ("scene", "knob", "setting", "backend", "pattern", "samples", "max_depth",
                   "threshold", "runs", "median_ms", "rmse", "max_abs", "psnr", "flip_mean",
                   "mismatched_fraction")
RAY_TEXTBOOK_SLOPES = TEXTBOOK_SLOPES | {
    "adaptive": ("none", "N is the mean traced: samples 5..N only where the first 4 disagree "
                 "(edges, shadow boundaries), so the error falls faster in N than jittered's, "
                 "until what the first 4 miss sets a floor"),
}
