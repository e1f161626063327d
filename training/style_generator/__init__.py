"""The style-conditioned locomotion generator (issue 39): train, pilot measures."""
