"""Checking images: the comparison of two frames and the pipeline tolerance, perceptual error,
golden-image policies, goldens, their report and the pytest plugin. Imports core, gpu and the
reference."""
