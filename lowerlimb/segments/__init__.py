"""From sensor orientations to segments: heading correction, ISB segment frames and joint angles."""

from lowerlimb.segments.angles import compute_joint_angles
from lowerlimb.segments.frames import SegmentFrames, segment_frames
from lowerlimb.segments.heading import HeadingCorrection, correct_headings
from lowerlimb.segments.tracking import SegmentMotion, track_segments

__all__ = [
    "HeadingCorrection",
    "SegmentFrames",
    "SegmentMotion",
    "compute_joint_angles",
    "correct_headings",
    "segment_frames",
    "track_segments",
]
