"""Errors that the CLI turns into one line on stderr and exit code 2."""


class RjcadError(Exception):
    """Base class: a user-facing problem with the input, never a bug."""


class ParameterError(RjcadError, ValueError):
    """A parameter is outside its allowed range.

    ``parameter`` names it as the user wrote it; ``limit`` states the range.
    """

    def __init__(self, parameter: str, value, limit: str, unit: str = ""):
        self.parameter = parameter
        self.value = value
        self.limit = limit
        self.unit = unit
        shown = f"{value:g}" if isinstance(value, float) else repr(value)
        super().__init__(f"{parameter} = {shown}{' ' + unit if unit else ''} is invalid: {limit}")


class InfeasibleDesign(RjcadError):
    """No design meets every constraint; ``constraint`` names the binding one."""

    def __init__(self, constraint: str, message: str):
        self.constraint = constraint
        super().__init__(message)
