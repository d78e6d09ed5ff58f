#pragma once
// One pass of the exact Euclidean distance transform (Felzenszwalb & Huttenlocher 2012): the
// lower envelope of the parabolas (x - q)^2 + f(q) over a line of n samples, O(n). Passes over
// each axis in turn give the squared distance transform of a 2D or 3D grid.
#include <vector>

namespace tgnav::planner {

// Scratch space of one line, reused between lines.
struct EnvelopeScratch {
  std::vector<int> v;
  std::vector<double> z;
};

// d[x] = min_q (x - q)^2 + f[q]; arg[x] = the minimising q. f may hold large values (1e20) for
// "no site"; at least one finite value keeps arg meaningful.
inline void lowerEnvelope(const double* f, int n, double* d, int* arg, EnvelopeScratch* s) {
  constexpr double kInf = 1e20;
  s->v.resize(n);
  s->z.resize(n + 1);
  int* v = s->v.data();
  double* z = s->z.data();
  int k = 0;
  v[0] = 0;
  z[0] = -kInf;
  z[1] = kInf;
  for (int q = 1; q < n; ++q) {
    double sx = 0.0;
    while (true) {
      const int p = v[k];
      sx = ((f[q] + static_cast<double>(q) * q) - (f[p] + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (sx > z[k] || k == 0) break;
      --k;
    }
    if (sx <= z[k]) {  // k == 0 and the new parabola dominates everywhere
      v[0] = q;
      z[1] = kInf;
      continue;
    }
    ++k;
    v[k] = q;
    z[k] = sx;
    z[k + 1] = kInf;
  }
  k = 0;
  for (int x = 0; x < n; ++x) {
    while (z[k + 1] < x) ++k;
    const int q = v[k];
    d[x] = static_cast<double>(x - q) * (x - q) + f[q];
    arg[x] = q;
  }
}

}  // namespace tgnav::planner
