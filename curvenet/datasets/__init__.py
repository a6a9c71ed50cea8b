"""Inputs whose truth is known: analytic shapes and their curve networks
(:mod:`.shapes`), CAD-like parts (:mod:`.cadnet`), a dense curved network of any size
(:mod:`.dense`), and redraw models that turn a network into a rough sketch
(:mod:`.redraw`; :mod:`.redraw_loops`, rings drawn as one stroke past or short of
their start)."""
