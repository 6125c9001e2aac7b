"""Real robots through the same contract: drivers that reach the hardware, and emulators of
that hardware backed by the simulation (see the submodules)."""
