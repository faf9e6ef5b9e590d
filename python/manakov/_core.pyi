"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

__all__ = [
    "ConvergenceError",
    "__version__",
]

__version__: str

class ConvergenceError(RuntimeError): ...
