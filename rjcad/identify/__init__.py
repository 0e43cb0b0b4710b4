"""Model critique from measured data: load a campaign, find what the design simulation gets wrong, name the cause."""
