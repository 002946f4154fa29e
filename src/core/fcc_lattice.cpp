// SPDX-License-Identifier: MIT
#include "fcc_lattice.h"

#include <cmath>

#include "../physics/boundary_integrals.h"
#include "../physics/kernels.h"
#include "../physics/surface_tension.h"

namespace sph {
namespace {

// Half the cubic cell: the step of the underlying simple-cubic grid.
double half_cell(float spacing) { return static_cast<double>(spacing) / std::sqrt(2.0); }

// The points of a box: the sub-lattice from lo with n[i] steps per axis.
struct BoxLattice {
  double lo[3];
  int64_t n[3];
  double step;
};

BoxLattice box_lattice(Vec3 min, Vec3 max, float spacing) {
  BoxLattice b;
  b.step = half_cell(spacing);
  const double margin = 0.5 * spacing;
  const double lo[3] = {min.x + margin, min.y + margin, min.z + margin};
  const double hi[3] = {max.x - margin, max.y - margin, max.z - margin};
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = lo[a];
    const double steps = hi[a] < lo[a] ? -1.0 : std::floor((hi[a] - lo[a]) / b.step);
    b.n[a] = steps < 0.0 ? 0 : (steps > 4e9 ? static_cast<int64_t>(4e9) : static_cast<int64_t>(steps) + 1);
  }
  return b;
}

// Calls visit(i, j, k, r2) for every FCC point (i + j + k even, in half-cell steps) closer than
// h to the origin, the origin included, always in the same order (so every lattice sum below is
// the same number on every machine).
template <class Visit>
void for_each_lattice_point_within(double step, double h, Visit&& visit) {
  const double h2 = h * h;
  const int64_t n = static_cast<int64_t>(std::ceil(h / step)) + 1;
  for (int64_t k = -n; k <= n; ++k)
    for (int64_t j = -n; j <= n; ++j)
      for (int64_t i = -n; i <= n; ++i) {
        if (((i + j + k) % 2 + 2) % 2 != 0) continue;
        const double r2 = step * step * static_cast<double>(i * i + j * j + k * k);
        if (r2 < h2) visit(i, j, k, r2);
      }
}

// The three faces a lattice sum over a flat surface averages: the integer normal (i, j, k) and
// the step of f . q between neighbouring lattice planes.
const int64_t kFccFaces[3][4] = {{1, 0, 0, 1}, {1, 1, 0, 1}, {1, 1, 1, 2}};

// The FCC point q of the plane f . q = plane nearest the origin (searched within 2 reach steps
// per axis, first found on a tie); false, and `best` untouched, if the search finds none.
bool nearest_point_on_plane(const int64_t f[4], int64_t plane, int64_t reach, int64_t best[3]) {
  int64_t best_norm = -1;
  for (int64_t k = -2 * reach; k <= 2 * reach; ++k)
    for (int64_t j = -2 * reach; j <= 2 * reach; ++j)
      for (int64_t i = -2 * reach; i <= 2 * reach; ++i) {
        if (((i + j + k) % 2 + 2) % 2 != 0 || f[0] * i + f[1] * j + f[2] * k != plane) continue;
        const int64_t n2 = i * i + j * j + k * k;
        if (best_norm < 0 || n2 < best_norm) {
          best_norm = n2;
          best[0] = i, best[1] = j, best[2] = k;
        }
      }
  return best_norm >= 0;
}

// Calls visit(d, r2) for every FCC point q of the half-space f . q <= 0 within reach steps per
// axis of p and closer than sqrt(h2), with d = (p - q) step, always in the same order.
template <class Visit>
void for_each_half_space_point_near(const int64_t f[4], const int64_t p[3], int64_t reach, double step,
                                    double h2, Visit&& visit) {
  for (int64_t k = p[2] - reach; k <= p[2] + reach; ++k)
    for (int64_t j = p[1] - reach; j <= p[1] + reach; ++j)
      for (int64_t i = p[0] - reach; i <= p[0] + reach; ++i) {
        if (((i + j + k) % 2 + 2) % 2 != 0 || f[0] * i + f[1] * j + f[2] * k > 0) continue;
        const double d[3] = {step * static_cast<double>(p[0] - i), step * static_cast<double>(p[1] - j),
                             step * static_cast<double>(p[2] - k)};
        const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (r2 < h2) visit(d, r2);
      }
}

}  // namespace

uint64_t fcc_box_point_count(Vec3 min, Vec3 max, float spacing) {
  const BoxLattice b = box_lattice(min, max, spacing);
  const double all = static_cast<double>(b.n[0]) * static_cast<double>(b.n[1]) * static_cast<double>(b.n[2]);
  if (all > 1.8e19) return UINT64_MAX;
  const uint64_t total =
      static_cast<uint64_t>(b.n[0]) * static_cast<uint64_t>(b.n[1]) * static_cast<uint64_t>(b.n[2]);
  // Points with an even index sum: half, plus one when every extent is odd (the corner counts).
  return (total + 1) / 2;
}

double fcc_sphere_point_estimate(float radius, float spacing) {
  const double r = radius, s = spacing;
  return 4.0 / 3.0 * 3.14159265358979323846 * r * r * r * std::sqrt(2.0) / (s * s * s);
}

HostVector<Vec3> fcc_points_in_box(Vec3 min, Vec3 max, float spacing) {
  const BoxLattice b = box_lattice(min, max, spacing);
  HostVector<Vec3> points;
  // A box without a lattice row along one axis holds no point, however long it is along the
  // others: return before the outer loops spin through them (a fuzzer found 1e9 empty turns).
  if (b.n[0] <= 0 || b.n[1] <= 0 || b.n[2] <= 0) return points;
  points.reserve(static_cast<size_t>(fcc_box_point_count(min, max, spacing)));
  for (int64_t k = 0; k < b.n[2]; ++k)
    for (int64_t j = 0; j < b.n[1]; ++j)
      for (int64_t i = 0; i < b.n[0]; ++i) {
        if ((i + j + k) % 2 != 0) continue;
        points.push_back(Vec3{static_cast<float>(b.lo[0] + b.step * static_cast<double>(i)),
                              static_cast<float>(b.lo[1] + b.step * static_cast<double>(j)),
                              static_cast<float>(b.lo[2] + b.step * static_cast<double>(k))});
      }
  return points;
}

HostVector<Vec3> fcc_points_in_sphere(Vec3 center, float radius, float spacing) {
  const double step = half_cell(spacing);
  const int64_t n = static_cast<int64_t>(std::floor(radius / step));
  const double r2 = static_cast<double>(radius) * radius;
  HostVector<Vec3> points;
  for (int64_t k = -n; k <= n; ++k)
    for (int64_t j = -n; j <= n; ++j)
      for (int64_t i = -n; i <= n; ++i) {
        if (((i + j + k) % 2 + 2) % 2 != 0) continue;
        const double x = step * static_cast<double>(i), y = step * static_cast<double>(j),
                     z = step * static_cast<double>(k);
        if (x * x + y * y + z * z > r2) continue;
        points.push_back(Vec3{static_cast<float>(center.x + x), static_cast<float>(center.y + y),
                              static_cast<float>(center.z + z)});
      }
  return points;
}

float fcc_rest_mass(float spacing, float kernel_radius, float rest_density) {
  const double step = half_cell(spacing);
  const KernelCoefficientsOf<double> k = make_kernel_coefficients<double>(kernel_radius);
  double sum = 0.0;
  for_each_lattice_point_within(step, k.h,
                                [&](int64_t, int64_t, int64_t, double r2) { sum += poly6(k, r2); });
  return static_cast<float>(rest_density / sum);
}

float fcc_spiky_scale(float spacing, float kernel_radius) {
  const double step = half_cell(spacing);
  const KernelCoefficientsOf<double> k = make_kernel_coefficients<double>(kernel_radius);
  double w_sum = 0.0;   // sum W_poly6: 1 / (rest volume m / rho0), as fcc_rest_mass
  double moment = 0.0;  // sum x_j |dW_spiky/dx| along x over the neighbours
  for_each_lattice_point_within(step, k.h, [&](int64_t i, int64_t, int64_t, double r2) {
    w_sum += poly6(k, r2);
    if (r2 == 0.0) return;
    const double r = std::sqrt(r2);
    const double x = step * static_cast<double>(i);
    moment += -spiky_gradient_magnitude(k, r) * x * x / r;
  });
  return static_cast<float>(w_sum / moment);
}

float fcc_density_self_weight(float spacing, float kernel_radius, float rest_density, float mass,
                              float spiky_scale) {
  const double step = half_cell(spacing);
  KernelCoefficientsOf<double> k = make_kernel_coefficients<double>(kernel_radius);
  k.spiky *= spiky_scale;  // as the world's float coefficients (FluidConstants)
  double sum = 0.0;
  for_each_lattice_point_within(step, k.h, [&](int64_t, int64_t, int64_t, double r2) {
    if (r2 == 0.0) return;  // the self term is what this returns
    sum += spiky_value(k, std::sqrt(r2));
  });
  return static_cast<float>(static_cast<double>(rest_density) / mass - sum);
}

uint32_t fcc_neighbor_count(float spacing, float kernel_radius) {
  uint32_t count = 0;
  for_each_lattice_point_within(half_cell(spacing), kernel_radius, [&](int64_t, int64_t, int64_t, double r2) {
    if (r2 > 0.0) ++count;
  });
  return count;
}

BoundaryCalibration fcc_boundary_calibration(float spacing, float kernel_radius) {
  const double step = half_cell(spacing);
  KernelCoefficientsOf<double> k = make_kernel_coefficients<double>(kernel_radius);
  k.spiky *= fcc_spiky_scale(spacing, kernel_radius);  // the world's density kernel
  k.spiky_grad *= fcc_spiky_scale(spacing, kernel_radius);
  const int64_t reach = static_cast<int64_t>(std::ceil(k.h / step)) + 1;
  // The (100) face: the particle on the first plane above f . q = 0; the half space f . q <= 0
  // is what a wall there takes away: its sum and that sum's slope along the wall's normal.
  const int64_t* f = kFccFaces[0];
  int64_t p[3] = {0, 0, 0};
  nearest_point_on_plane(f, f[3], reach, p);
  double missing = 0.0, slope = 0.0;
  for_each_half_space_point_near(f, p, reach, step, k.h2, [&](const double* d, double r2) {
    const double r = std::sqrt(r2);
    missing += spiky_value(k, r);
    slope += -spiky_gradient_magnitude(k, r) * d[0] / r;  // d/dx of the sum as the particle nears the wall
  });
  // The continuous share's slope over value, (7.5 h - 6 a) / (a (1.5 h - a)) with a = h - d,
  // falls from infinity at a = 0 to 3 / h at a = h: bisect for 2 slope / missing.
  const double h = k.h, target = 2.0 * slope / missing;
  double lo = 1e-9 * h, hi = h;
  for (int i = 0; i < 200; ++i) {
    const double a = 0.5 * (lo + hi);
    if ((7.5 * h - 6.0 * a) / (a * (1.5 * h - a)) > target)
      lo = a;
    else
      hi = a;
  }
  const double effective = h - 0.5 * (lo + hi);  // the first layer's distance from the shifted wall
  BoundaryCalibration c;
  c.scale = missing / spiky_half_space<double>(effective, h);
  c.offset = effective - 0.5 * static_cast<double>(spacing);
  return c;
}

double fcc_surface_delta_integral(float spacing, float kernel_radius, float threshold) {
  const double step = half_cell(spacing);
  const KernelCoefficientsOf<double> k = make_kernel_coefficients<double>(kernel_radius);
  const double h = k.h;
  const double h2 = k.h2;
  const double cell_volume = 2.0 * step * step * step;  // volume per lattice point
  const int64_t reach = static_cast<int64_t>(std::ceil(h / step)) + 1;
  // Rest volume m / rho0 = 1 / sum_lattice W (fcc_rest_mass).
  double w_sum = 0.0;
  for_each_lattice_point_within(step, h,
                                [&](int64_t, int64_t, int64_t, double r2) { w_sum += poly6(k, r2); });
  const double volume = 1.0 / w_sum;
  double total = 0.0;
  for (const auto& f : kFccFaces) {
    const double norm = std::sqrt(static_cast<double>(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    const double layer_gap = static_cast<double>(f[3]) * step / norm;
    double integral = 0.0;
    // Every plane of a Bravais lattice is one orbit of in-plane translations, so one point per
    // plane (the one nearest the origin) stands for all; area per point = cell_volume / gap.
    for (int64_t layer = 0; static_cast<double>(layer) * step / norm < h; layer += f[3]) {
      int64_t best[3] = {0, 0, 0};
      nearest_point_on_plane(f, -layer, reach, best);
      // Colour gradient at that point from the fluid half-space u . q <= 0.
      double g[3] = {0.0, 0.0, 0.0};
      for_each_half_space_point_near(f, best, reach, step, h2, [&](const double d[3], double r2) {
        const double c = poly6_gradient_factor(k, r2) * volume;
        for (int a = 0; a < 3; ++a) g[a] += c * d[a];
      });
      const double length = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
      if (length > threshold) integral += volume * (length - threshold) * layer_gap / cell_volume;
    }
    total += integral;
  }
  return total / 3.0;
}

namespace {

// C(r) with its coefficient 32 / (pi h^9), in double.
double cohesion_c(double h, double r) {
  if (r <= 0.0 || r >= h) return 0.0;
  return cohesion_coefficient(h, 1.0) * cohesion_spline(h, r);
}

// Phi(r) = int_r^h C: 4-point Gauss-Legendre on each polynomial piece (degree 6, exact).
double cohesion_potential(double h, double r) {
  static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                              0.8611363115940526};
  static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  auto integrate = [&](double a, double b) {
    double s = 0.0;
    for (int k = 0; k < 4; ++k) s += w[k] * cohesion_c(h, 0.5 * (a + b) + 0.5 * (b - a) * x[k]);
    return 0.5 * (b - a) * s;
  };
  if (r >= h) return 0.0;
  if (2.0 * r >= h) return integrate(r, h);
  return integrate(r, 0.5 * h) + integrate(0.5 * h, h);
}

}  // namespace

CohesionLattice fcc_cohesion_lattice(float spacing, float kernel_radius) {
  const double step = half_cell(spacing);
  const double h = kernel_radius;
  const double h2 = h * h;
  const double cell_volume = 2.0 * step * step * step;  // volume per lattice point
  const int64_t reach = static_cast<int64_t>(std::ceil(h / step)) + 1;
  CohesionLattice out{0.0, 0.0};
  // Bulk virial: one particle and its neighbours.
  double virial = 0.0;
  for_each_lattice_point_within(step, h, [&](int64_t, int64_t, int64_t, double r2) {
    if (r2 <= 0.0) return;
    const double r = std::sqrt(r2);
    virial += cohesion_c(h, r) * r;
  });
  out.bulk_pressure = virial / (6.0 * cell_volume);
  // Separation energy: for each lattice plane of B (u . q = layer > 0) one point stands for the
  // plane (every plane is one orbit of in-plane translations; area per point cell_volume / gap),
  // and sums Phi over the points of A (u . q <= 0).
  double total = 0.0;
  for (const auto& f : kFccFaces) {
    const double norm = std::sqrt(static_cast<double>(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    const double layer_gap = static_cast<double>(f[3]) * step / norm;
    double energy = 0.0;
    for (int64_t layer = f[3]; static_cast<double>(layer - f[3]) * step / norm < h; layer += f[3]) {
      int64_t best[3] = {0, 0, 0};
      if (!nearest_point_on_plane(f, layer, reach, best)) continue;
      double sum = 0.0;
      for_each_half_space_point_near(f, best, reach, step, h2, [&](const double*, double r2) {
        sum += cohesion_potential(h, std::sqrt(r2));
      });
      energy += sum * layer_gap / cell_volume;
    }
    total += 0.5 * energy;
  }
  out.surface_energy = total / 3.0;
  return out;
}

}  // namespace sph
