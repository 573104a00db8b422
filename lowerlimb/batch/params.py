"""How a study is processed: every option and threshold of ``lowerlimb batch`` in one place."""

from __future__ import annotations

from dataclasses import dataclass, field

from lowerlimb.io.result_files import OUTPUT_FILES

__all__ = ["ALL_OUTPUTS", "BatchParams"]

#: Short names of every file of a result folder (:data:`lowerlimb.io.result_files.OUTPUT_FILES`).
ALL_OUTPUTS: frozenset[str] = frozenset(OUTPUT_FILES)


@dataclass(frozen=True)
class BatchParams:
    """Options of a study run (defaults: ``lowerlimb calibrate``'s).

    Attributes:
        method: joint-constraint solver (:data:`lowerlimb.methods.CALIBRATION_METHODS`).
        filter_name: orientation filter (:data:`lowerlimb.methods.ORIENTATION_FILTERS`).
        use_mag: fuse the magnetometer when a trial has one.
        centre_form: the joint constraint that decides the hip and knee centres
            (:data:`lowerlimb.methods.CENTRE_FORMS`; ``calibrate --centre-form``).
        hip_in_pelvis_form: the form that places the hip centre in the pelvis sensor
            (``calibrate --hip-in-pelvis-form``). Always part of the input hash: studies run
            before it became ``"aligned"`` are re-run once.
        thigh_twist: undo each thigh sensor's turn about the femur with hip flexion
            (``calibrate --thigh-twist``; in the input hash only when on).
        side_check: refuse a trial whose calibrated hip lies on the other side of the
            pelvis sensor (``calibrate --no-side-check``; in the input hash only when off).
        order_check: refuse a trial whose sensor columns look swapped
            (``calibrate --no-order-check``; in the input hash only when off).
        sign_check: refuse a trial in which a sensor turns about the vertical against its
            neighbours (``calibrate --no-sign-check``; in the input hash only when off).
        smooth_orientation: the orientation filters run forward and backward (offline;
            ``False``: ``calibrate --causal``). Always part of the input hash: studies run
            before the two passes became the default are re-run once.
        outputs: short names of the files written per trial.
        workers: local worker processes; ``None``: one per core.
        force: redo trials whose outputs are complete and up to date.
        retries: times a trial whose worker process died is run again (alone) before
            it is marked failed.
        default_side: leg of the trials whose manifest row gives none.
        default_height_m: stature of the subjects whose row gives none, m.
        default_mass_kg: mass of the subjects whose row gives none, kg.
        summary_every_s: batch.csv is rewritten at most this often while running, s
            (and always at the end).
    """

    method: str = "casadi"
    filter_name: str = "mahony"
    use_mag: bool = True
    centre_form: str = "norm"
    hip_in_pelvis_form: str = "aligned"
    thigh_twist: bool = False
    side_check: bool = True
    order_check: bool = True
    sign_check: bool = True
    smooth_orientation: bool = True
    outputs: frozenset[str] = field(default=ALL_OUTPUTS)
    workers: int | None = None
    force: bool = False
    retries: int = 1
    default_side: str = "left"
    default_height_m: float = 1.75
    default_mass_kg: float = 75.0
    summary_every_s: float = 30.0

    def processing_key(self) -> dict[str, object]:
        """The options that change a trial's outputs (part of its input hash)."""
        key: dict[str, object] = {
            "method": self.method,
            "filter": self.filter_name,
            "use_mag": self.use_mag,
            "outputs": sorted(self.outputs),
        }
        if self.centre_form != "norm":  # the default leaves the studies run before it up to date
            key["centre_form"] = self.centre_form
        key["hip_in_pelvis_form"] = self.hip_in_pelvis_form  # its default changed the results
        key["smooth_orientation"] = self.smooth_orientation  # so did this one's
        if self.thigh_twist:  # off leaves the studies run before it up to date
            key["thigh_twist"] = True
        for name in ("side_check", "order_check", "sign_check"):
            if not getattr(self, name):  # on (the default) leaves the studies run before them up to date
                key[name] = False
        return key
