"""The fixed settings of `renderer report`: sizes, targets, the CSV's columns and the textbook
convergence rates, read by the sweep (report.py, shadow_report.py) and by its output
(report_output.py)."""

from dataclasses import dataclass

DEFAULT_SIZE = (160, 120)
# The sweeps a report can run, by name: `--quick` (CI's: a minute or two), the default (the
# built-in scenes in under 30 minutes on the project's 2-core machine:
# benchmarks/results/report.md) and `--exhaustive` (every sample count, 5 runs: hours).
SWEEP_NAMES = ("quick", "standard", "exhaustive")
SWEEP_FLAGS = {"quick": " --quick", "standard": "", "exhaustive": " --exhaustive"}
QUICK_SIZE = (64, 48)
QUICK_SCENES = ("flat_shading", "gouraud_vs_phong")
# The errors the "cheapest setting" must reach: about 2.6/255, where one sample often does,
# and about 0.8/255, where the patterns part ways.
TARGETS_RMSE = (0.01, 0.003)
MISMATCH_LEVELS = 2                  # of 255: a pixel further off than this is mismatched
BASE_SAMPLES = 4                     # regular grid for the knobs other than antialiasing
# The shadow knobs' errors against ray-cast truth (renderer/checks/shadow_truth.py), empty in
# the other knobs' rows, whose image errors (rmse .. mismatched_fraction) are empty in theirs.
SHADOW_COLUMNS = ("wrong_outside_band_fraction", "wrong_fraction", "acne_pixels",
                  "peter_panning_max_texels")
# The output knob's (renderer/study/output_report.py): against the linear frame, not the truth.
OUTPUT_COLUMNS = ("method", "bits", "block_mean_abs", "block_p95_abs", "block_max_abs",
                  "block_bias", "lowpass_psnr")
# `worker` (host:pid) names the process that timed the row: the report may run on several
# (renderer/study/report_units.py), and only the times depend on where a row ran.
CSV_COLUMNS = ("scene", "knob", "setting", "backend", "pattern", "samples", "runs", "median_ms",
               "worker", "rmse", "max_abs", "psnr", "flip_mean", "mismatched_fraction", *SHADOW_COLUMNS,
               *OUTPUT_COLUMNS)


@dataclass(frozen=True)
class ShadowTarget:
    """What the shadow knobs' "cheapest setting" must reach, as fractions of all pixels."""
    wrong_outside_band: float          # wrong outside the 1-texel band: below this
    wrong: float                       # wrong in all (inside the band too): at most this
    acne_pixels: int                   # at most this many

    def met(self, row: dict) -> bool:
        return (row["wrong_outside_band_fraction"] < self.wrong_outside_band
                and row["wrong_fraction"] <= self.wrong and row["acne_pixels"] <= self.acne_pixels)

    def text(self) -> str:
        total = f", at most {self.wrong:.2%} wrong in all" if self.wrong < 1.0 else ""
        return (f"fewer than {self.wrong_outside_band:.1%} of pixels wrong outside the 1-texel "
                f"band{total}, {self.acne_pixels} acne pixels")


# Issue 15's bar for the default settings, then a sharper one that also bounds the errors
# within a texel of the true edge (which only a finer map or a wider filter lowers).
SHADOW_TARGETS = (ShadowTarget(0.001, 1.0, 0), ShadowTarget(0.001, 0.002, 0))
SHADOW_RESOLUTIONS = (256, 512, 1024, 2048, 4096)    # the resolution knob's maps

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
# Radiosity's report (renderer/study/radiosity_report.py, radiosity_report_output.py).
RADIOSITY_DEFAULT_SIZE = (160, 120)
RADIOSITY_QUICK_SIZE = (64, 48)
RADIOSITY_QUICK_SCENES = ("cornell_box_radiosity",)
RADIOSITY_MAX_SIZE = (320, 240)      # its path-traced truth: 4096 paths a pixel on the GPU
TWIN_ACROSS = 6                      # the twin's element sizes: at most this many across
RADIOSITY_CSV_COLUMNS = ("scene", "knob", "setting", "backend", "samples", "elements_across", "hemicube",
                         "iterations", "runs", "median_ms", "worker", "rmse", "max_abs", "psnr",
                         "flip_mean", "mismatched_fraction")
QUICK_SCENES_OF = {"raster": QUICK_SCENES, "raytrace": RAY_QUICK_SCENES,      # --quick's, by method
                   "radiosity": RADIOSITY_QUICK_SCENES}
RAY_MAX_SIZE = (320, 240)            # its ground truth traces 1024 rays per pixel in float64
RAY_BASE_SAMPLES = 16                # jittered, for the knobs other than antialiasing
RAY_CSV_COLUMNS = ("scene", "knob", "setting", "backend", "pattern", "samples", "light_samples",
                   "max_depth", "threshold", "runs", "median_ms", "worker", "rmse", "max_abs", "psnr", "flip_mean",
                   "mismatched_fraction")
RAY_TEXTBOOK_SLOPES = TEXTBOOK_SLOPES | {
    "adaptive": ("none", "N is the mean traced: samples 5..N only where the first 4 disagree "
                 "(edges, shadow boundaries), so the error falls faster in N than jittered's, "
                 "until what the first 4 miss sets a floor"),
}

# The ray tracer's distributed effects (renderer/study/distributed_report.py): a knob per
# dimension; with antialiasing, the knobs whose series are sampling patterns.
EFFECT_KNOBS = ("lens", "time", "glossy")
DISTRIBUTED_KNOBS = ("light_samples", *EFFECT_KNOBS)
PATTERN_KNOBS = ("antialiasing", *DISTRIBUTED_KNOBS)
