"""Machines put together from the CPU and chips, with no more hardware than a scene needs."""
