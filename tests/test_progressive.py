"""renderer/viewer/progressive.py: the viewer's running mean of ray-traced frames, fed frames by
hand and by a stand-in tracer, and one-sample frames of a RayTracer against its frame of all
those samples (EGL): the mean of linear colour weighted by samples, coverage
where any sample hit, restarts, the cap, and the sample indices each frame asks for."""

import numpy as np
import pytest

from renderer.core.frame import Frame
from renderer.core.gl_rules import to_unorm8
from renderer.gpu.raytracer import RayTracer
from renderer.viewer.progressive import MAX_SPP, PATTERN, SAMPLES_PER_FRAME, Accumulator


def frame(colour, covered=True, size=(3, 2)):
    """A frame of one colour, covered (alpha 1) or not (alpha 0) everywhere."""
    width, height = size
    linear = np.empty((height, width, 4), np.float32)
    linear[..., :3] = colour
    linear[..., 3] = 1.0 if covered else 0.0
    return Frame(to_unorm8(linear), linear)


def test_the_mean_is_of_samples_weighted_by_each_frames_count():
    acc = Accumulator()
    acc.add(frame((0.25, 0.5, 1.0)), 1)
    acc.add(frame((0.75, 0.0, 0.5), covered=False), 3)       # the mean of three samples
    assert acc.samples == 4
    assert np.allclose(acc.linear[0, 0, :3], [(0.25 + 3 * 0.75) / 4, 0.5 / 4, (1 + 1.5) / 4])
    assert (acc.linear[..., 3] == 1).all()                    # some sample hit: covered
    assert (acc.rgba8 == to_unorm8(acc.linear)).all() and (acc.rgba8[..., 3] == 255).all()


def test_one_frame_is_shown_as_it_is():
    one = frame((0.1, 1.7, -0.2), covered=False)              # unclamped linear colour
    acc = Accumulator()
    acc.add(one, 1)
    assert acc.linear.tobytes() == one.linear.tobytes()
    assert (acc.rgba8 == one.rgba8).all() and (acc.rgba8[..., 3] == 0).all()


def test_restart_forgets_every_sample():
    acc = Accumulator()
    acc.add(frame((1.0, 1.0, 1.0)), 1)
    acc.restart()
    assert acc.samples == 0 and not acc.done
    with pytest.raises(ValueError, match="no frame"):
        acc.linear
    acc.add(frame((0.5, 0.5, 0.5), size=(4, 4)), 1)           # another size after a restart
    assert acc.samples == 1 and np.allclose(acc.linear[..., :3], 0.5)
    with pytest.raises(ValueError, match="restart first"):
        acc.add(frame((0.5, 0.5, 0.5), size=(3, 2)), 1)


class StandInTracer:
    """Frames whose colour is the first sample index asked for, over 8."""

    def __init__(self):
        self.asked = []

    def render(self, first_sample=0):
        self.asked.append(first_sample)
        return frame((first_sample / 8, 0.0, 0.0))


def test_trace_asks_for_new_samples_each_frame_and_stops_at_the_cap():
    tracer, acc = StandInTracer(), Accumulator(cap=3)
    for _ in range(5):
        acc.trace(tracer)
    assert acc.samples == 3 and acc.done
    assert tracer.asked == [0, 1, 2]
    assert acc.linear[0, 0, 0] == pytest.approx((0 + 1 + 2) / 3 / 8)
    acc.restart()
    acc.trace(tracer)
    assert tracer.asked[-1] == 0 and acc.samples == 1


def test_one_sample_frames_add_up_to_the_frame_of_all_their_samples(gl_contexts):
    """Frames of sample 0, 1, 2, 3 averaged are the 4-sample frame of the same pattern, up to
    the float32 sums (the GLSL sums its samples in float32, the mean here in float64)."""
    from renderer.core.scene_file import scene_from_dict
    scene = scene_from_dict({"camera": {"eye": [0, 0, 4]}, "objects": [
        {"shape": {"type": "sphere", "radius": 1.0}, "material": {"kd": [0.9, 0.5, 0.2]}}],
        "lights": [{"type": "directional", "direction": [-1, -1, -1]}]})
    acc = Accumulator()
    assert acc.cap == MAX_SPP and not acc.done
    with RayTracer(scene, 24, 18, context=gl_contexts["egl"], samples=SAMPLES_PER_FRAME,
                   pattern=PATTERN) as tracer:
        for _ in range(4):
            acc.trace(tracer)
        first = tracer.render(first_sample=0)
    with RayTracer(scene, 24, 18, context=gl_contexts["egl"], samples=4, pattern=PATTERN) as tracer:
        whole = tracer.render()
    assert acc.samples == 4 and (acc.linear != first.linear).any()
    assert np.allclose(acc.linear, whole.linear, rtol=0, atol=1e-6)
    assert np.abs(acc.rgba8.astype(int) - whole.rgba8).max() <= 1
    with pytest.raises(ValueError):
        Accumulator(cap=0)


@pytest.mark.slow                       # a tracer compiled per scene; 80 frames each
@pytest.mark.parametrize("name", ["soft_shadows", "depth_of_field", "motion_blur", "glossy"])
def test_the_viewer_converges_on_each_distributed_effect(name, gl_contexts):
    """Issue 16: each one-sample frame draws a new light point, lens point, time and lobe
    direction (the sample index is the frame's), so the viewer's mean converges on the
    effect: its RMSE against the mean of 64 later frames (samples 16 to 79) falls from 1 to 4
    to 16 frames."""
    from renderer.core.scene_file import load_scene
    size = (32, 24)
    with RayTracer(load_scene(name), *size, context=gl_contexts["egl"], samples=SAMPLES_PER_FRAME,
                   pattern=PATTERN) as tracer:
        acc, means = Accumulator(), {}
        for frames in range(1, 17):
            acc.trace(tracer)
            if frames in (1, 4, 16):
                means[frames] = np.clip(acc.linear[..., :3], 0, 1)
        truth = np.clip(np.mean([tracer.render(first_sample=k).linear[..., :3]
                                 for k in range(16, 80)], axis=0), 0, 1)
    rmse = {n: float(np.sqrt(((image - truth) ** 2).mean())) for n, image in means.items()}
    assert rmse[1] > rmse[4] > rmse[16], rmse
