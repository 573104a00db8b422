"""Writers for other tools' formats, from plain arrays.

OpenSim/OpenSense (:mod:`.opensim`), BIDS-motion (:mod:`.bids`) and units
sidecars for our CSV tables (:mod:`.units`).
"""
