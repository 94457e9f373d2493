"""Runtime pieces that put bendpam's moment law inside simulators (:mod:`bendpam.sim.mujoco`)."""
