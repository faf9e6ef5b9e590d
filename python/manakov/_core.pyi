"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

__version__: str

class ConvergenceError(RuntimeError): ...
