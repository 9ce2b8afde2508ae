"""The sensor as the equipment has it: the beam's spot, the amplifier's thresholds, the axis's
motion and latching, and the sensor's settings as users write them."""
