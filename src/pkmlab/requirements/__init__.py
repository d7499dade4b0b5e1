"""Design to requirements: required workspaces (task regions × orientation sets), required
motions with a payload, inverse dynamics of the platform and actuator selection.

* :mod:`.task` — task regions and the exact containment check, margins, geometry for drawing;
* :mod:`.motions` — required motions: CSV recordings, sinusoids, the paper's motion, with
  velocities and accelerations;
* :mod:`.payload` — rigid-body mass properties (platform, payload, lumped leg masses);
* :mod:`.dynamics` — Newton–Euler inverse dynamics → actuator forces, speeds and powers;
* :mod:`.actuators` — actuator specifications, catalogues and the fit check;
* :mod:`.plots` — actuator force / speed / torque–speed plots (matplotlib Figure, no pyplot).
"""
