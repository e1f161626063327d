"""Datasets and caches: the CMU locomotion clips, their per-frame features, the acLSTM dance set, and the commands that build and report on them."""
