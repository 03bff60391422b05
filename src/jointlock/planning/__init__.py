"""Planning after a lock: halt configuration and motion, velocity-jump compensation, re-planning."""
