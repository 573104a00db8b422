"""Domain-free optimisers. Never imports lowerlimb."""
