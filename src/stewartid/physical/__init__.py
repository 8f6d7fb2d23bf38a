"""The rigid-body ("physical") model identified from the logs: payload and platform masses,
first moments and inertias, friction per joint type and sensor offsets, valid over the
workspace; Mt and Bt at any pose follow from them."""
