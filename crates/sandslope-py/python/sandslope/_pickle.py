"""Reconstructors that pickle records by name for Robot and Terrain (Dask ships them to
worker processes): each object pickles as its plain dict and is validated again on load."""

from ._sandslope import Robot, Terrain


def robot(spec):
    """Rebuilds a Robot from ``Robot.to_dict()``."""
    return Robot(**spec)


def terrain(spec):
    """Rebuilds a Terrain from ``Terrain.to_dict()``."""
    return Terrain(**spec)
