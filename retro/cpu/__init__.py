"""The CPU harness: 6502 cores (py65-based), the bus with devices, and the Machine that runs routines."""

from retro.cpu.machine import CallResult, Machine, TraceEntry

__all__ = ["CallResult", "Machine", "TraceEntry"]
