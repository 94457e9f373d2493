"""Design tools: fingers under in-plane loads, grippers grasping spheres, and a four-actuator wrist.

* :mod:`bendpam.design.finger`: planar statics of a finger (rod along the frame line, the paper's
  moment law section by section), tip pose, blocked tip force, tip stiffness.
* :mod:`bendpam.design.grasp`: an N-finger gripper closing on a sphere, contact and pull-out force
  (the paper's Figure 8 test).
* :mod:`bendpam.design.wrist`: four BC-PAMs around a column (the paper's Figure 9 wrist): bending
  angle and direction, holding capacity.

Units: mm, N, N*mm, MPa for pressures passed to functions (kPa in table columns), rad (degrees in
names ending ``_deg``), grams for masses.
"""
