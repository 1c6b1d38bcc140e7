"""Studies of the renderers: error against run time (`renderer report`: supersampling, sample
accumulation, tessellation, ground truth) and the extreme cases (`renderer extremes`).
Imports core, gpu, checks and the reference."""
