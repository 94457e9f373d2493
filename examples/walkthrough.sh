#!/usr/bin/env bash
# The README's story, in order, in one empty folder: predict -> simulate a test -> inspect and
# process -> fit -> report -> a finger -> a design from targets -> a sweep -> the hand and its wrist.
# Run it from an empty folder as `bash PATH/TO/bendpam/examples/walkthrough.sh` (it writes into the folder it
# runs in); tests/test_walkthrough.py runs it and checks what it writes, and that the numbers README.md and docs/tutorial.md quote are what it prints.
set -euo pipefail

# 1. Predict the paper's BE-PAM, and save it as an editable actuator file
bendpam predict --preset be-pam --pressure-kpa 100 150 200
bendpam actuator --preset be-pam --out be.toml

# 2. A virtual cyclic test (four-point bending, 5 pressures) written as Zwick testXpert exports
bendpam simulate-test --actuator be.toml --pressure-kpa 100:200:5 --out raw-be --table-format testxpert --seed 1

# 3. What the reader understands of the files, then Table 2 quantities and Figure 4
bendpam inspect raw-be
bendpam process raw-be --out processed-be

# 4. Identify alpha0, C10, C01 (Table 3) and predict with the fitted actuator
bendpam fit processed-be --actuator be.toml --out fit-be
bendpam predict --actuator fit-be/fitted_actuator.toml --pressure-kpa 100 150 200

# 5. A test with a pronounced friction loop (fitted with both branches by default), and the predicted cycle
bendpam simulate-test --preset be-pam --pressure-kpa 100:200:5 --out raw-loop --hysteresis 0.10 \
    --hysteresis-law pi --hysteresis-angle-deg 12 --seed 2
bendpam process raw-loop --out processed-loop
bendpam fit processed-loop --preset be-pam --out fit-loop
bendpam predict --actuator fit-loop/fitted_actuator.toml --pressure-kpa 150 --cycle

# 6. One HTML page from the raw files: Table 2, Table 3 for both models, Figures 4 and 7
bendpam report raw-be --actuator be.toml --out report-be.html

# 7. A finger made of the fitted actuator, loaded at its tip
bendpam finger --actuator fit-be/fitted_actuator.toml --pressure-kpa 100 150 200 --tip-force-n 0,-0.5 \
    --plot finger.png

# 8. Design from targets: 400 N*mm blocked and 90 deg free at 200 kPa, every margin >= 1.5 up to 250 kPa
bendpam design --preset be-pam --target blocked_moment_nmm=400@200 --target free_angle_deg=90@200 \
    --vary alpha0_deg=60:80 --vary R0_mm=6:12 --vary t0_mm=1:3 --max-pressure-kpa 250 --min-margin 1.5 --out design-be
bendpam predict --actuator design-be/design.toml --pressure-kpa 200

# 9. A design sweep over the braid angle and the bladder wall
bendpam sweep --preset be-pam --param alpha0_deg=60:80:21 --param t0_mm=1.5:3:4 --pressure-kpa 100:250:16 \
    --out sweep.nc --plot sweep.png

# 10. The soft humanoid hand: its Kapandji test, and the wrist carrying the hand and a 550 g bottle
bendpam hand --kapandji --out hand
bendpam wrist --preset bc-pam --pressure-kpa 140 --payload-g 550 --quiet
