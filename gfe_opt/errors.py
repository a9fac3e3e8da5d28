"""Exceptions raised for bad input and failed solves."""


class GfeInputError(ValueError):
    """Bad input: the message is one line naming the file (or argument), the field and the fault.

    Raised by every reader and validator in gfe-opt; the CLI prints it and exits with code 2.
    """

    def __init__(self, where: str | None, field: str | None, problem: str):
        self.where, self.field, self.problem = where, field, problem
        parts = [p for p in (where, field) if p]
        super().__init__(": ".join(parts + [problem]))


class GfeSolverError(RuntimeError):
    """A numerical solve failed (eigen solver, optimiser); the message carries its status."""
