"""Where a beam meets a wafer: the exact segment-disc test and the paper's, accessibility, the
closed-form range of scan positions over which a beam hits a wafer, and the bowed wafer's surfaces."""
