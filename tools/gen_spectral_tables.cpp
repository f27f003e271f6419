// Build-time generator of nimbus's spectral tables (docs/spectra.md):
//
//   gen_spectral_tables CMF_FILE D65_FILE OUTPUT.cpp
//
// reads the CIE 1931 2° colour matching functions and the D65 illuminant from colord-data's
// IT8-like files, resamples them every 5 nm over [360, 830] nm, fits the Jakob and Hanika (2019)
// RGB-to-spectrum coefficient table under D65, and writes all three as C++ arrays (declared in
// src/nimbus/spectral/spectral_tables.h). Any malformed input stops it with a message naming
// the file and line.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "nimbus/spectral/color.h"
#include "nimbus/spectral/spectral_tables.h"

namespace {

using namespace nimbus;
using namespace nimbus::spectral_tables;

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "gen_spectral_tables: " << message << "\n";
  std::exit(1);
}

// ---------------------------------------------------------------------------------------------
// Parsing

// The parts of an IT8-like spectral file that matter here: the wavelengths of the bands and the
// data sets (one row of SPECTRAL_BANDS values each).
struct SpectralFile {
  std::string path;
  double start_nm = 0, end_nm = 0;
  int bands = 0;
  std::vector<std::vector<double>> sets;
};

std::optional<double> parse_number(const std::string& token) {
  double v = 0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

SpectralFile parse_spectral_file(const std::string& path, int expected_sets) {
  std::ifstream in(path);
  if (!in) fail(path + ": cannot open");
  SpectralFile f;
  f.path = path;
  std::optional<double> start, end, bands, sets;
  std::vector<double> data;
  enum class State { Header, Format, Data, Done } state = State::Header;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    std::istringstream tokens(line);
    std::string key;
    if (!(tokens >> key)) continue;
    if (state == State::Format) {
      if (key == "END_DATA_FORMAT") state = State::Header;
      continue;
    }
    if (state == State::Data) {
      if (key == "END_DATA") {
        state = State::Done;
        continue;
      }
      std::string token = key;
      do {
        const auto v = parse_number(token);
        if (!v) fail(where + "'" + token + "' is not a number");
        data.push_back(*v);
      } while (tokens >> token);
      continue;
    }
    if (state == State::Done) {
      fail(where + "unexpected '" + key + "' after END_DATA");
    }
    std::optional<double>* field = key == "SPECTRAL_START_NM" ? &start
                                   : key == "SPECTRAL_END_NM" ? &end
                                   : key == "SPECTRAL_BANDS"  ? &bands
                                   : key == "NUMBER_OF_SETS"  ? &sets
                                                              : nullptr;
    if (field) {
      std::string value, extra;
      if (!(tokens >> value) || (tokens >> extra)) fail(where + key + " needs one value");
      if (*field) fail(where + key + " given twice");
      *field = parse_number(value);
      if (!*field) fail(where + key + " value '" + value + "' is not a number");
    } else if (key == "BEGIN_DATA_FORMAT") {
      state = State::Format;
    } else if (key == "BEGIN_DATA") {
      state = State::Data;
    } else if (key == "END_DATA" || key == "END_DATA_FORMAT") {
      fail(where + key + " without its BEGIN");
    }
    // Other header keywords (DISPLAY, ORIGINATOR, ...) carry nothing needed here.
  }
  if (state == State::Format) fail(path + ": BEGIN_DATA_FORMAT without END_DATA_FORMAT");
  if (state == State::Data) fail(path + ": BEGIN_DATA without END_DATA");
  if (state == State::Header) fail(path + ": no BEGIN_DATA section");
  if (!start || !end || !bands) {
    fail(path + ": SPECTRAL_START_NM, SPECTRAL_END_NM and SPECTRAL_BANDS are all required");
  }
  if (*bands != std::floor(*bands) || *bands < 2 || *bands > 100000) {
    fail(path + ": SPECTRAL_BANDS must be an integer >= 2");
  }
  if (!(*end > *start)) fail(path + ": SPECTRAL_END_NM must exceed SPECTRAL_START_NM");
  f.start_nm = *start;
  f.end_nm = *end;
  f.bands = static_cast<int>(*bands);
  if (sets && *sets != expected_sets) {
    std::ostringstream m;
    m << path << ": NUMBER_OF_SETS is " << *sets << ", expected " << expected_sets;
    fail(m.str());
  }
  if (data.size() != static_cast<size_t>(expected_sets) * f.bands) {
    fail(path + ": " + std::to_string(data.size()) + " data values, expected " +
         std::to_string(expected_sets) + " sets of " + std::to_string(f.bands));
  }
  for (int s = 0; s < expected_sets; ++s) {
    f.sets.emplace_back(data.begin() + s * f.bands, data.begin() + (s + 1) * f.bands);
  }
  for (size_t i = 0; i < data.size(); ++i) {
    if (data[i] < 0) {
      std::ostringstream m;
      m << path << ": negative value " << data[i] << " (set " << i / f.bands + 1 << ", band "
        << i % f.bands + 1 << ")";
      fail(m.str());
    }
  }
  return f;
}

// One data set linearly interpolated onto the 5 nm grid over [kLambdaMin, kLambdaMax]; exact
// (a copy) when the file's bands fall on that grid, as colord-data's do.
std::array<double, kBands> resample(const SpectralFile& f, int set) {
  const double step = (f.end_nm - f.start_nm) / (f.bands - 1);
  if (f.start_nm > kLambdaMin + 1e-9 || f.end_nm < kLambdaMax - 1e-9) {
    std::ostringstream m;
    m << f.path << ": covers [" << f.start_nm << ", " << f.end_nm << "] nm, need [" << kLambdaMin
      << ", " << kLambdaMax << "]";
    fail(m.str());
  }
  std::array<double, kBands> out{};
  for (int i = 0; i < kBands; ++i) {
    const double x = (kLambdaMin + i * kStep - f.start_nm) / step;
    const int j = std::clamp(static_cast<int>(std::floor(x)), 0, f.bands - 2);
    const double t = std::clamp(x - j, 0.0, 1.0);
    out[i] = (1 - t) * f.sets[set][j] + t * f.sets[set][j + 1];
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Fitting (Jakob and Hanika 2019, sec. 4)

// reflectance_to_rgb restricted to sigmoid curves: rgb(c) = Σ_k W_k S(q_c(t_k)), with W_k the
// trapezoid weight times linear sRGB of D65 · (x̄, ȳ, z̄) at λ_k, over ∫ D65 ȳ; the same sum that
// nimbus::reflectance_to_rgb computes at run time.
class SigmoidRgb {
 public:
  SigmoidRgb(const std::array<std::array<double, kBands>, 3>& cmf,
             const std::array<double, kBands>& d65) {
    double norm = 0;
    for (int k = 0; k < kGridPoints; ++k) {
      const double lambda = grid_lambda(k);
      const double d = grid_weight(k) * lerp(d65, lambda);
      const Vec3 xyz{d * lerp(cmf[0], lambda), d * lerp(cmf[1], lambda), d * lerp(cmf[2], lambda)};
      norm += xyz.y;
      const Rgb rgb = xyz_to_linear_srgb(xyz);
      for (int c = 0; c < 3; ++c) w_[k][c] = rgb[c];
      t_[k] = (lambda - kMidNm) / kWidthNm;
    }
    for (auto& w : w_)
      for (double& v : w) v /= norm;
  }

  // The RGB of coefficients c = (A, B, C) of A t² + B t + C, and its Jacobian ∂rgb_i / ∂c_j.
  void eval(const std::array<double, 3>& c, std::array<double, 3>& rgb,
            std::array<std::array<double, 3>, 3>& jac) const {
    rgb = {};
    jac = {};
    for (int k = 0; k < kGridPoints; ++k) {
      const double t = t_[k];
      const double q = (c[0] * t + c[1]) * t + c[2];
      const double r = 1 / std::sqrt(1 + q * q);
      const double s = 0.5 + 0.5 * q * r;  // S(q)
      const double ds = 0.5 * r * r * r;   // S'(q)
      const double basis[3] = {t * t, t, 1};
      for (int i = 0; i < 3; ++i) {
        rgb[i] += w_[k][i] * s;
        for (int j = 0; j < 3; ++j) jac[i][j] += w_[k][i] * ds * basis[j];
      }
    }
  }

  // Levenberg–Marquardt from the warm start c, minimising |rgb(c) − target|²; returns the final
  // residual's largest component. An unreachable target ends with the best coefficients found
  // when no damped step improves or after kMaxIterations: in practice only RGB (1, 1, 1), as the
  // constant 1 gives (1.00024, 0.99997, 0.99960) because the white of the CIE D65 data is not
  // exactly sRGB's (0.3127, 0.3290).
  double fit(const std::array<double, 3>& target, std::array<double, 3>& c) const {
    std::array<double, 3> rgb;
    std::array<std::array<double, 3>, 3> jac;
    eval(c, rgb, jac);
    std::array<double, 3> r;
    double err = 0;
    for (int i = 0; i < 3; ++i) r[i] = rgb[i] - target[i], err += r[i] * r[i];
    double mu = 1e-6;
    for (int it = 0; it < kMaxIterations && err > kTolerance * kTolerance; ++it) {
      double a[3][3], g[3];
      for (int i = 0; i < 3; ++i) {
        g[i] = 0;
        for (int k = 0; k < 3; ++k) g[i] += jac[k][i] * r[k];
        for (int j = 0; j < 3; ++j) {
          a[i][j] = 0;
          for (int k = 0; k < 3; ++k) a[i][j] += jac[k][i] * jac[k][j];
        }
      }
      const double trace = a[0][0] + a[1][1] + a[2][2];
      bool improved = false;
      for (; mu < 1e10 && !improved; mu *= 10) {
        std::array<double, 3> step;
        if (!solve_damped(a, g, mu * trace / 3, step)) continue;
        std::array<double, 3> c_new, rgb_new, r_new;
        std::array<std::array<double, 3>, 3> jac_new;
        for (int i = 0; i < 3; ++i) c_new[i] = c[i] - step[i];
        eval(c_new, rgb_new, jac_new);
        double err_new = 0;
        for (int i = 0; i < 3; ++i)
          r_new[i] = rgb_new[i] - target[i], err_new += r_new[i] * r_new[i];
        if (err_new < err) {
          improved = true;
          c = c_new, jac = jac_new, r = r_new, err = err_new;
          mu = std::max(mu * 1e-2, 1e-13);  // the loop's mu *= 10 follows: net ÷10
        }
      }
      if (!improved) break;
    }
    return std::max({std::abs(r[0]), std::abs(r[1]), std::abs(r[2])});
  }

  static constexpr int kMaxIterations = 50;
  static constexpr double kTolerance = 1e-9;

 private:
  static double lerp(const std::array<double, kBands>& v, double lambda) {
    return interpolate(v.data(), lambda);
  }

  // Solves (a + damping I) x = g by Cholesky; false when not positive definite.
  static bool solve_damped(const double (&a)[3][3], const double (&g)[3], double damping,
                           std::array<double, 3>& x) {
    double l[3][3] = {};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j <= i; ++j) {
        double s = a[i][j] + (i == j ? damping : 0);
        for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
        if (i == j) {
          if (!(s > 0)) return false;
          l[i][i] = std::sqrt(s);
        } else {
          l[i][j] = s / l[j][j];
        }
      }
    }
    double y[3];
    for (int i = 0; i < 3; ++i) {
      y[i] = g[i];
      for (int k = 0; k < i; ++k) y[i] -= l[i][k] * y[k];
      y[i] /= l[i][i];
    }
    for (int i = 2; i >= 0; --i) {
      x[i] = y[i];
      for (int k = i + 1; k < 3; ++k) x[i] -= l[k][i] * x[k];
      x[i] /= l[i][i];
    }
    return true;
  }

  std::array<double, kGridPoints> t_;
  std::array<std::array<double, 3>, kGridPoints> w_;
};

struct Table {
  std::vector<float> coeffs = std::vector<float>(kTableSize);
  double max_residual = 0;  // of the fits' RGB, over all nodes
};

Table fit_table(const SigmoidRgb& model) {
  Table table;
  std::vector<double> residual(kTableSize / 3);
  // Columns (l, y, x) are independent; within one, z goes up from kZMin, each fit warm-started
  // from its neighbour's solution (as in the paper's code).
  tbb::parallel_for(tbb::blocked_range<int>(0, 3 * kXyRes * kXyRes), [&](const auto& range) {
    for (int column = range.begin(); column != range.end(); ++column) {
      const int l = column / (kXyRes * kXyRes), yi = column / kXyRes % kXyRes, xi = column % kXyRes;
      const double x = xy_node(xi), y = xy_node(yi);
      std::array<double, 3> c{};
      for (int k = 0; k < kZRes; ++k) {
        const double z = z_node(k);
        std::array<double, 3> target;
        target[l] = z;
        target[(l + 1) % 3] = x * z;
        target[(l + 2) % 3] = y * z;
        const int index = table_index(l, k, yi, xi);
        residual[index / 3] = model.fit(target, c);
        for (int i = 0; i < 3; ++i) table.coeffs[index + i] = static_cast<float>(c[i]);
      }
    }
  });
  for (double r : residual) table.max_residual = std::max(table.max_residual, r);
  return table;
}

// ---------------------------------------------------------------------------------------------
// Output

void write_array(std::ostream& out, const double* v, int n) {
  out << "{";
  for (int i = 0; i < n; ++i) out << (i ? ", " : "") << v[i];
  out << "}";
}

void write_output(const std::string& path, const SpectralFile& cmf_file,
                  const SpectralFile& d65_file,
                  const std::array<std::array<double, kBands>, 3>& cmf,
                  const std::array<double, kBands>& d65, const Table& table) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) fail(tmp + ": cannot write");
    out.precision(std::numeric_limits<double>::max_digits10);
    out << "// Generated by tools/gen_spectral_tables.cpp from\n//   " << cmf_file.path << "\n//   "
        << d65_file.path << "\n// Do not edit.\n\n"
        << "#include \"nimbus/spectral/spectral_tables.h\"\n\n"
        << "namespace nimbus::spectral_tables {\n\n";
    out << "const double kCmf[3][kBands] = {";
    for (int c = 0; c < 3; ++c) {
      out << (c ? ",\n" : "\n");
      write_array(out, cmf[c].data(), kBands);
    }
    out << "};\n\nconst double kD65[kBands] = ";
    write_array(out, d65.data(), kBands);
    out << ";\n\n";
    out << "const uint32_t kCoeffBits[kTableSize] = {";
    char word[16];
    for (int i = 0; i < kTableSize; ++i) {
      std::snprintf(word, sizeof word, "0x%08x,",
                    static_cast<unsigned>(std::bit_cast<uint32_t>(table.coeffs[i])));
      out << (i % 12 ? "" : "\n") << word;
    }
    out << "};\n\n}  // namespace nimbus::spectral_tables\n";
    if (!out) fail(tmp + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail(path + ": " + ec.message());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) fail("usage: gen_spectral_tables CMF_FILE D65_FILE OUTPUT.cpp");
  const auto t0 = std::chrono::steady_clock::now();
  const SpectralFile cmf_file = parse_spectral_file(argv[1], 3);
  const SpectralFile d65_file = parse_spectral_file(argv[2], 1);
  const std::array<std::array<double, kBands>, 3> cmf = {
      resample(cmf_file, 0), resample(cmf_file, 1), resample(cmf_file, 2)};
  const std::array<double, kBands> d65 = resample(d65_file, 0);
  const Table table = fit_table(SigmoidRgb(cmf, d65));
  write_output(argv[3], cmf_file, d65_file, cmf, d65, table);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("gen_spectral_tables: %d coefficient sets fitted in %.2f s; max RGB residual %.2e\n",
              kTableSize / 3, seconds, table.max_residual);
  return 0;
}
