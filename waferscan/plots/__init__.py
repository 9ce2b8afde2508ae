"""Pictures drawn with matplotlib from what ``core`` computed: the signal b(z), the pockets seen
from above, the sweep's plots, the bench's costs. Nothing here computes a result."""
