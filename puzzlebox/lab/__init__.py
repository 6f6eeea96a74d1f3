"""The composition layer: the one package that imports the twin, the skills, the learning layer and the real arm
together, to run trials, sweeps, datasets, calibrations, reports and the twin experiments (DESIGN.md)."""
