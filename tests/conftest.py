import os

from hypothesis import HealthCheck, settings

# CI (the default): the same examples every run, so that a landing never depends on luck;
# HYPOTHESIS_PROFILE=dev explores new random examples.
settings.register_profile("ci", deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
settings.register_profile("dev", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
