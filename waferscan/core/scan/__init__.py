"""One scan of a layout: the engines, the ideal and the real sensor's scan, its result and
warnings, slow scanning's jab and sweep at each pocket, the pocket plan and calibration."""
