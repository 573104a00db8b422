"""Pictures of a result: the meshcat scene, the HTML report, the live view and plots.

Import the modules themselves (:mod:`lowerlimb.viz.report`, :mod:`lowerlimb.viz.view`…):
this package imports nothing, so that a plot does not pull in meshcat.
"""

__all__: list[str] = []
