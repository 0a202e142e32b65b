"""The trial planner: the cheapest agenda predicted to meet an accuracy target at a site, chosen by
campaigns (a sequential, surrogate-guided search) and verified by larger campaigns of it and of the
agenda one step cheaper."""

from vtrials.plan.search import plan  # noqa: F401
