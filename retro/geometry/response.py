"""Collision response: separate along the MTV, bounce with a restitution coefficient, or slide.

Sign convention (the one `sat`, `aabb_mtv` and `circle_mtv` return): `normal` is a unit vector and
moving body a by normal * depth separates it from body b, i.e. the normal points from b towards a.
Masses are > 0; pass math.inf for an immovable body (a wall).
"""

from __future__ import annotations

import math

from retro.errors import InputError
from retro.geometry.vectors import Number, PointLike, as_number, as_point

Vec = tuple[float, float]


def _inverse_mass(mass: object, name: str) -> float:
    if isinstance(mass, (int, float)) and not isinstance(mass, bool) and mass == math.inf:
        return 0.0
    m = as_number(mass, name)
    if m <= 0:
        raise InputError(f"{name}: must be > 0 (math.inf for an immovable body), got {m}")
    return 1.0 / m


def _unit(normal: PointLike) -> Vec:
    nx, ny = as_point(normal, "normal")
    length = math.hypot(nx, ny)
    if abs(length - 1) > 1e-9:
        raise InputError(f"normal: must be a unit vector, has length {length}")
    return float(nx), float(ny)


def separate(pos_a: PointLike, pos_b: PointLike, normal: PointLike, depth: Number,
             mass_a: Number = 1.0, mass_b: Number = 1.0) -> tuple[Vec, Vec]:
    """Positional correction: move a along +normal and b along -normal, sharing `depth` in inverse
    proportion to mass, so that they just touch. Returns the new (pos_a, pos_b)."""
    ax, ay = as_point(pos_a, "pos_a")
    bx, by = as_point(pos_b, "pos_b")
    nx, ny = _unit(normal)
    d = as_number(depth, "depth")
    if d < 0:
        raise InputError(f"depth: must be >= 0, got {d}")
    inv_a, inv_b = _inverse_mass(mass_a, "mass_a"), _inverse_mass(mass_b, "mass_b")
    if inv_a + inv_b == 0:
        raise InputError("mass: two immovable bodies cannot be separated")
    share_a = inv_a / (inv_a + inv_b)
    share_b = 1.0 - share_a
    return (ax + nx * d * share_a, ay + ny * d * share_a), (bx - nx * d * share_b, by - ny * d * share_b)


def bounce(vel_a: PointLike, vel_b: PointLike, normal: PointLike, restitution: Number,
           mass_a: Number = 1.0, mass_b: Number = 1.0) -> tuple[Vec, Vec]:
    """Impulse response along the contact normal. Restitution e in [0, 1]: the normal component
    of the relative velocity after the collision is -e times the one before (0: no bounce, the
    bodies move together along the normal; 1: full bounce, kinetic energy conserved). Momentum is
    conserved for any e. Bodies already moving apart are returned unchanged. Tangential velocity
    is untouched (no friction). Returns the new (vel_a, vel_b)."""
    vax, vay = as_point(vel_a, "vel_a")
    vbx, vby = as_point(vel_b, "vel_b")
    nx, ny = _unit(normal)
    e = as_number(restitution, "restitution")
    if not 0 <= e <= 1:
        raise InputError(f"restitution: must be in [0, 1], got {e}")
    inv_a, inv_b = _inverse_mass(mass_a, "mass_a"), _inverse_mass(mass_b, "mass_b")
    if inv_a + inv_b == 0:
        raise InputError("mass: two immovable bodies cannot bounce")
    approach = (vax - vbx) * nx + (vay - vby) * ny  # < 0: a moves towards b along the normal
    if approach >= 0:
        return (float(vax), float(vay)), (float(vbx), float(vby))
    j = -(1 + e) * approach / (inv_a + inv_b)  # impulse magnitude along the normal
    return ((vax + j * inv_a * nx, vay + j * inv_a * ny), (vbx - j * inv_b * nx, vby - j * inv_b * ny))


def slide(velocity: PointLike, normal: PointLike) -> Vec:
    """Remove the part of the velocity that pushes into the surface (v . n < 0), keeping the
    tangential part: the body slides along the wall. Moving away from the surface is unchanged."""
    vx, vy = as_point(velocity, "velocity")
    nx, ny = _unit(normal)
    into = vx * nx + vy * ny
    if into >= 0:
        return float(vx), float(vy)
    return vx - into * nx, vy - into * ny
