"""Mass properties against shapely (area, centroid) and closed-form inertia."""

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import MultiPoint, Polygon

from geometry_library import GeometryError, mass_properties


def random_convex(rng: np.random.Generator, offset=(0.0, 0.0)) -> np.ndarray:
    """Convex hull of random points, CCW, without closing repeat."""
    pts = rng.uniform(-1.0, 1.0, size=(rng.integers(3, 25), 2)) * rng.uniform(0.05, 3.0, size=2)
    hull = MultiPoint([tuple(p) for p in pts]).convex_hull
    hull = shapely.geometry.polygon.orient(hull, 1.0)
    return np.asarray(hull.exterior.coords)[:-1] + np.asarray(offset)


def triangle_fan_inertia(xy: np.ndarray, rho_e: float) -> tuple[float, np.ndarray, float]:
    """Independent reference: fan of triangles (mean point, vertex i, vertex i+1), each with the
    closed-form polar moment about its own centroid J = A (|ab|² + |bc|² + |ca|²) / 36, moved to
    the polygon centroid by the parallel-axis theorem."""
    c0 = xy.mean(axis=0)
    total_a, moment, tris = 0.0, np.zeros(2), []
    for i in range(len(xy)):
        a, b, c = c0, xy[i], xy[(i + 1) % len(xy)]
        area = 0.5 * ((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
        g = (a + b + c) / 3.0
        j = area / 36.0 * (np.sum((b - a) ** 2) + np.sum((c - b) ** 2) + np.sum((a - c) ** 2))
        tris.append((area, g, j))
        total_a += area
        moment += area * g
    centroid = moment / total_a
    j_c = sum(j + area * np.sum((g - centroid) ** 2) for area, g, j in tris)
    return total_a, centroid, rho_e * j_c


@pytest.mark.parametrize("seed", range(20))
def test_random_convex_polygons_match_shapely_and_triangle_sum(seed):
    rng = np.random.default_rng(seed)
    xy = random_convex(rng, offset=rng.uniform(-50, 50, size=2))
    props = mass_properties(xy, density=2300.0, thickness=0.7)
    poly = Polygon(xy)
    assert props.area == pytest.approx(poly.area, rel=1e-12)
    assert props.mass == pytest.approx(2300.0 * 0.7 * poly.area, rel=1e-12)
    np.testing.assert_allclose(props.centroid, [poly.centroid.x, poly.centroid.y], rtol=0, atol=1e-10)
    area, centroid, inertia = triangle_fan_inertia(xy - xy.mean(axis=0), 2300.0 * 0.7)
    assert props.inertia == pytest.approx(inertia, rel=1e-9)


@pytest.mark.parametrize("w,h", [(0.3, 0.2), (0.6, 0.2), (1.0, 1.0), (2.5, 0.05)])
def test_rectangle_inertia_is_m_w2_plus_h2_over_12(w, h):
    xy = np.array([[10.0, 5.0], [10.0 + w, 5.0], [10.0 + w, 5.0 + h], [10.0, 5.0 + h]])
    props = mass_properties(xy, density=2500.0, thickness=1.0)
    m = 2500.0 * w * h
    assert props.mass == pytest.approx(m, rel=1e-13)
    assert props.inertia == pytest.approx(m * (w * w + h * h) / 12.0, rel=1e-12)
    np.testing.assert_allclose(props.centroid, [10.0 + w / 2, 5.0 + h / 2], atol=1e-13)


def test_clockwise_input_and_closing_repeat_give_the_same_result():
    xy = random_convex(np.random.default_rng(7))
    ccw = mass_properties(xy)
    cw = mass_properties(xy[::-1])
    closed = mass_properties(np.vstack([xy, xy[:1]]))
    for other in (cw, closed):
        assert other.area == pytest.approx(ccw.area, rel=1e-13)
        assert other.inertia == pytest.approx(ccw.inertia, rel=1e-12)
        np.testing.assert_allclose(other.centroid, ccw.centroid, atol=1e-14)
    assert ccw.area > 0 and ccw.inertia > 0


def test_disc_polygon_inertia_tends_to_half_m_r2():
    theta = np.linspace(0.0, 2 * math.pi, 2000, endpoint=False)
    xy = np.c_[np.cos(theta), np.sin(theta)] * 0.5
    props = mass_properties(xy, density=1.0, thickness=1.0)
    assert props.inertia == pytest.approx(0.5 * props.mass * 0.25, rel=1e-5)


@pytest.mark.parametrize(
    "xy",
    [
        [[0, 0], [1, 0]],
        [[0, 0], [1, 0], [2, 0]],
        [[0, 0], [1, 0], [np.nan, 1]],
    ],
)
def test_degenerate_input_raises(xy):
    with pytest.raises(GeometryError):
        mass_properties(np.asarray(xy, dtype=float))


def test_non_positive_density_raises():
    with pytest.raises(GeometryError, match="density"):
        mass_properties([[0, 0], [1, 0], [0, 1]], density=0.0)
