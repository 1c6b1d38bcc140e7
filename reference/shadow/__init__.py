"""The reference's shadow maps (docs/conventions.md, "Shadows"): the depth pass that draws each
light's map into its layer of the array texture (depth.py) and the lookup that asks it whether
a light reaches a point (lookup.py). The rules both twins read are renderer/core/shadows.py and
renderer/core/shadow_settings.py.
"""
