"""The pipeline tolerance: when the GPU and the reference (or any two renders of one scene)
agree, written once. `renderer compare`, `renderer extremes`, the viewer's reference view and
every GPU-against-reference test read it from here.

The rule is dEQP's threshold compare with position deviation (renderer/checks/compare.py):
- no pixel may fail the compare: every pixel of each image has one within ±`deviation`
  pixels in the other that matches within `threshold`/255 on every channel;
- at most `raw_mismatch_limit` of the pixels (0.1 %) may differ by more than `threshold` in
  place (edges that moved by a pixel, which the first rule forgives, must stay rare);
- where both drew, depth agrees within `depth_rel_limit` relative (1e-3), with the same
  ±`deviation` allowance (a neighbour's depth, or the neighbour's surface continued by one
  pixel: an edge-on silhouette's depth changes faster than the limit per pixel).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerance:
    threshold: int = 2                   # of 255, per channel
    deviation: int = 1                   # pixels
    max_mismatched_pixels: int = 0       # pixels failing even with the deviation allowed
    raw_mismatch_limit: float = 0.001    # fraction of pixels off by more than threshold in place
    depth_rel_limit: float = 1e-3        # largest relative depth difference where both drew

    def failures(self, comparison) -> list[str]:
        """What a comparison (a compare.Comparison or its as_dict()) breaks, one line per
        rule; empty when it meets the tolerance. A comparison without depth skips that rule."""
        figures = comparison if isinstance(comparison, dict) else comparison.as_dict()
        failed = []
        if figures["mismatched_pixels"] > self.max_mismatched_pixels:
            failed.append(f"{figures['mismatched_pixels']} pixels fail within ±{self.deviation} px "
                          f"at {self.threshold}/255 (at most {self.max_mismatched_pixels} may)")
        if figures["raw_mismatched_fraction"] > self.raw_mismatch_limit:
            failed.append(f"{figures['raw_mismatched_fraction']:.4%} of pixels differ by more than "
                          f"{self.threshold}/255 in place (at most {self.raw_mismatch_limit:.1%})")
        depth = figures.get("depth_max_rel")
        if depth is not None and not depth <= self.depth_rel_limit:
            failed.append(f"depth differs by {depth:.3g} relative (at most {self.depth_rel_limit:g})")
        return failed

    def passes(self, comparison) -> bool:
        return not self.failures(comparison)

    def describe(self) -> str:
        return (f"{self.max_mismatched_pixels} mismatched pixels within ±{self.deviation} px at {self.threshold}/255, raw <= "
                f"{self.raw_mismatch_limit}, depth <= {self.depth_rel_limit:g}")


PIPELINE_TOLERANCE = Tolerance()
