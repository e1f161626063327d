"""Reading CMU motion capture: ASF/AMC and BVH readers, rotations, the canonical skeleton and its FK, retargeting, resampling, foot contacts."""
