"""Virtual instruments: sample the true state on their own clocks and apply composable error models
(see vtrials.instruments.parts and /work/shared/docs/instruments.md)."""
