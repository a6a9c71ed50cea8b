"""Inputs whose truth is known: analytic shapes and their curve networks, CAD-like parts, redraw models of rough sketches."""

