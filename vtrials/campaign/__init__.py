"""Monte Carlo campaigns: many randomized replicates of a trial agenda, every reduced quantity
scored against truth, and the honesty of its interval measured (coverage, sharpness)."""

from vtrials.campaign.run import run_campaign  # noqa: F401
