#include "report/explorer.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/grid.h"
#include "core/hash.h"
#include "core/incidences.h"
#include "core/json_text.h"
#include "core/packed_array.h"
#include "core/setting.h"
#include "core/stokes.h"
#include "core/table.h"
#include "lamina/version.h"
#include "report/assets.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace fs = std::filesystem;
using nlohmann::json;

namespace lamina {

namespace {

// ---- Reading the study directory ------------------------------------------------------------

// The largest JSON file of a study folder read (a configuration's state and stack are tens of
// kB; the bound keeps a device or a runaway file from being read without end).
constexpr std::size_t kMaxStudyJsonBytes = std::size_t(256) << 20;

json read_json(const fs::path& path, const char* what) {
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw InputError(path.string(), "",
                         fmt::format("cannot read {} (is this a study directory written by `lamina "
                                     "study` or `lamina compare`?)",
                                     what));
    const std::string text = read_regular_file_bounded(path, kMaxStudyJsonBytes, what);
    try {
        return json::parse(text);
    } catch (const json::exception& e) {
        throw InputError(path.string(), "",
                         fmt::format("malformed JSON: {}", json_exception_text(e)));
    }
}

// A file's bytes for a digest: a regular file's (within the tables' bound), else nothing.
std::string digest_bytes(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) > kMaxTableFileBytes) return {};
    return read_file_bounded(path, kMaxTableFileBytes, "the file");
}

template <class T>
T field(const json& j, const std::string& key, const fs::path& file) {
    if (!j.contains(key)) throw InputError(file.string(), "/" + key, "missing");
    try {
        return j.at(key).get<T>();
    } catch (const json::exception& e) {
        throw InputError(file.string(), "/" + key,
                         fmt::format("wrong type: {}", json_exception_text(e)));
    }
}

std::vector<std::string> split_csv_line(const std::string& line) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : line) {
        if (c == ',') {
            out.push_back(cur);
            cur.clear();
        } else if (c != '\r') {
            cur += c;
        }
    }
    out.push_back(cur);
    return out;
}

// One incidence of a configuration: θi, and φi (0 on a folded configuration).
struct Incidence {
    double theta_i = 0, phi_i = 0;
};
using ConfigIncidences = std::map<std::string, std::vector<Incidence>>;

// metrics.csv → {config: {model: {side: {metric: [incidence][channel]}}}}, null where empty. The
// incidences are the study's θi, or an unfolded configuration's own (θi, φi) (`unfolded`).
json read_metrics(const fs::path& path, const std::vector<double>& theta_i,
                  const ConfigIncidences& unfolded) {
    json out = json::object();
    std::error_code ec;
    if (!fs::exists(path, ec)) return out;  // the page then shows no leaderboard, and says so
    std::istringstream in(read_regular_file_bounded(path, kMaxTableFileBytes, "the metrics table"));
    std::string line;
    std::getline(in, line);
    const std::vector<std::string> header = split_csv_line(line);
    auto column = [&](const char* name) {
        const auto it = std::find(header.begin(), header.end(), name);
        if (it == header.end()) throw InputError(path.string(), name, "column missing");
        return std::size_t(it - header.begin());
    };
    const std::size_t c_config = column("config"), c_model = column("model"),
                      c_theta = column("theta_i"), c_side = column("side"),
                      c_channel = column("channel"), c_supported = column("supported");
    // A study with light off φ = 0 has a phi_i column (docs/formats.md).
    const std::size_t c_phi =
        std::size_t(std::find(header.begin(), header.end(), "phi_i") - header.begin());
    const bool has_phi = c_phi < header.size();
    std::vector<std::pair<const char*, std::size_t>> metrics = {{"me", column("misplaced_energy")},
                                                                {"nf", column("noise_floor")},
                                                                {"ae", column("albedo_error")},
                                                                {"lr", column("log_rmse")}};
    // The floored misplaced energy and its noise floor: absent from studies written before them.
    for (const auto& [key, name] :
         {std::pair{"mf", "misplaced_floor"}, std::pair{"nf_mf", "misplaced_floor_noise"}})
        if (std::find(header.begin(), header.end(), name) != header.end())
            metrics.emplace_back(key, column(name));
    std::size_t row = 1;
    while (std::getline(in, line)) {
        ++row;
        if (line.empty()) continue;
        const std::vector<std::string> v = split_csv_line(line);
        if (v.size() != header.size())
            throw InputError(path.string(), fmt::format("row {}", row),
                             fmt::format("{} fields, the header has {}", v.size(), header.size()));
        // A decimal number, as metrics.csv holds (its writer leaves a value not computed empty).
        const auto number = [&](std::size_t col) {
            double x = 0;
            if (!setting_detail::parse_real(v[col], x))
                throw InputError(path.string(), fmt::format("row {}, {}", row, header[col]),
                                 fmt::format("'{}' is not a finite number", v[col]));
            return x;
        };
        const double t = number(c_theta);
        const double phi = has_phi ? number(c_phi) : 0.0;
        std::size_t i = 0, n = theta_i.size();
        if (const auto u = unfolded.find(v[c_config]); u != unfolded.end()) {
            n = u->second.size();
            while (i < n && (std::abs(u->second[i].theta_i - t) > 1e-6 ||
                             std::abs(u->second[i].phi_i - phi) > 1e-6))
                ++i;
        } else {
            while (i < n && (std::abs(theta_i[i] - t) > 1e-6 || phi != 0))
                ++i;
        }
        if (i == n) continue;  // an incidence study.json does not list
        const int ch = v[c_channel] == "r" ? 0 : v[c_channel] == "g" ? 1 : 2;
        json& cell = out[v[c_config]][v[c_model]][v[c_side]];
        for (const auto& [key, col] : metrics) {
            if (!cell.contains(key)) cell[key] = json::array();
            json& arr = cell[key];
            while (arr.size() < n)
                arr.push_back(json{nullptr, nullptr, nullptr});
            if (v[c_supported] != "true" || v[col].empty()) continue;
            // As the study writes them (its state's check): within the tables' bound, the
            // misplaced energies, their floors and the log RMSE never negative.
            const double x = number(col);
            const bool nonnegative = std::string_view(key) != "ae";
            if (!(std::abs(x) <= kMaxBinValue) || (nonnegative && x < 0))
                throw InputError(path.string(), fmt::format("row {}, {}", row, header[col]),
                                 fmt::format("{} is outside {}", v[col],
                                             nonnegative ? "[0, 1e12]" : "[-1e12, 1e12]"));
            arr[i][ch] = x;
        }
    }
    return out;
}

// ---- Encoding ---------------------------------------------------------------------------------

std::string base64(const void* data, std::size_t n) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const auto* p = static_cast<const unsigned char*>(data);
    std::string out;
    out.reserve((n + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < n; i += 3) {
        const unsigned v = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
        out += k[v >> 18];
        out += k[(v >> 12) & 63];
        out += k[(v >> 6) & 63];
        out += k[v & 63];
    }
    if (i + 1 == n) {
        const unsigned v = p[i] << 16;
        out += k[v >> 18];
        out += k[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == n) {
        const unsigned v = (p[i] << 16) | (p[i + 1] << 8);
        out += k[v >> 18];
        out += k[(v >> 12) & 63];
        out += k[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

// The hemisphere maps are stored as 16-bit codes of log10 f (docs/explorer.md, "Data"): 0 is
// f <= 0, 65535 is NaN (not supported), 1..65534 cover [lo, hi] in log10 f uniformly. Ten decades
// over 65533 steps: a relative step of 0.035 %, invisible on any map.
constexpr double kLogDecades = 10.0;
constexpr std::uint16_t kCodeNaN = 65535;

struct LogCodec {
    double lo = -10.0, hi = 0.0;
    std::uint16_t encode(float f) const {
        if (std::isnan(f)) return kCodeNaN;
        if (!(f > 0)) return 0;
        const double u = (std::log10(double(f)) - lo) / (hi - lo);
        return std::uint16_t(1 + std::lround(std::clamp(u, 0.0, 1.0) * 65533.0));
    }
};

// Ω⊥ of each θ row's bins on the grid of docs/formats.md with n_phi φ bins, folded or unfolded
// (2 · the folded count): the grid's own (HemisphereGrid::projected_solid_angle, the same for
// every φ bin of a row).
std::vector<double> omega_perp_rows(std::size_t n_theta, std::size_t n_phi, bool unfolded) {
    const HemisphereGrid folded{int(n_theta), int(unfolded ? n_phi / 2 : n_phi)};
    const HemisphereGrid grid = unfolded ? folded.unfolded() : folded;
    std::vector<double> rows(n_theta);
    for (std::size_t t = 0; t < n_theta; ++t)
        rows[t] = grid.projected_solid_angle(int(t), 0);
    return rows;
}

// Groups of `k` consecutive bins (the last one may be shorter): the edges of the merged bins.
std::vector<int> merged_edges(int n, int k) {
    std::vector<int> e;
    for (int i = 0; i < n; i += k)
        e.push_back(i);
    e.push_back(n);
    return e;
}

// A table whose last three axes are θ bin, φ bin, channel, seen as consecutive blocks of
// T × P × 3 floats: block (s·I + i)·D + d of tables.lza, block i·D + d of reference_se.lza.
struct BinBlocks {
    const std::vector<float>& data;
    std::size_t T, P;
    bool unfolded = false;  ///< P bins over φ ∈ [0°, 360°)
    std::size_t blocks() const { return data.size() / (T * P * 3); }
    float at(std::size_t block, std::size_t t, std::size_t p, std::size_t c) const {
        return data[((block * T + t) * P + p) * 3 + c];
    }
};

// The unfolded φ bins the half-plane at azimuth `phi_deg` runs through: the bin it crosses, or
// the two it separates when it lies on an edge (equal Ω⊥: their mean is the plane's value).
std::vector<std::size_t> plane_bins(std::size_t P, double phi_deg) {
    const double width = 360.0 / double(P);
    const double u = std::fmod(std::fmod(phi_deg, 360.0) + 360.0, 360.0) / width;
    const double k = std::round(u);
    if (std::abs(u - k) < 1e-9) return {(std::size_t(k) + P - 1) % P, std::size_t(k) % P};
    return {std::size_t(std::floor(u)) % P};
}

// The incident plane of every block at full resolution, [block, 2T, 3]: x < T is the light's
// side (θ descending), x >= T the mirror side (θ ascending). Folded: φ bin 0 and the last φ bin.
// Unfolded (`phi_i`: each block's incidence azimuth, blocks = sources × incidences × sides):
// the half-planes φ = φi and φ = φi + 180°.
std::vector<float> incident_plane(const BinBlocks& b, const std::vector<double>& phi_i = {},
                                  std::size_t sides = 1) {
    std::vector<float> out;
    out.reserve(b.blocks() * 2 * b.T * 3);
    for (std::size_t k = 0; k < b.blocks(); ++k) {
        if (!b.unfolded) {
            for (std::size_t x = 0; x < 2 * b.T; ++x)
                for (std::size_t c = 0; c < 3; ++c)
                    out.push_back(x < b.T ? b.at(k, b.T - 1 - x, 0, c)
                                          : b.at(k, x - b.T, b.P - 1, c));
            continue;
        }
        const double phi = phi_i[(k / sides) % phi_i.size()];
        const std::vector<std::size_t> light = plane_bins(b.P, phi),
                                       mirror = plane_bins(b.P, phi + 180);
        auto mean = [&](const std::vector<std::size_t>& bins, std::size_t t, std::size_t c) {
            double v = 0;
            for (std::size_t p : bins)
                v += b.at(k, t, p, c);
            return float(v / double(bins.size()));
        };
        for (std::size_t x = 0; x < 2 * b.T; ++x)
            for (std::size_t c = 0; c < 3; ++c)
                out.push_back(x < b.T ? mean(light, b.T - 1 - x, c) : mean(mirror, x - b.T, c));
    }
    return out;
}

// Bins merged into groups (edges `et` × `ep`), [block, T2, P2, 3]. Values: the cos-weighted
// average Σ f_j Ω⊥_j / Σ Ω⊥_j; standard errors (`quadrature`): √Σ (se_j Ω⊥_j)² / Σ Ω⊥_j, the
// bins taken as independent.
std::vector<float> merge_bins(const BinBlocks& b, const std::vector<int>& et,
                              const std::vector<int>& ep, bool quadrature) {
    std::vector<float> out;
    out.reserve(b.blocks() * (et.size() - 1) * (ep.size() - 1) * 3);
    const std::vector<double> omega = omega_perp_rows(b.T, b.P, b.unfolded);
    for (std::size_t k = 0; k < b.blocks(); ++k)
        for (std::size_t t2 = 0; t2 + 1 < et.size(); ++t2)
            for (std::size_t p2 = 0; p2 + 1 < ep.size(); ++p2)
                for (std::size_t c = 0; c < 3; ++c) {
                    double num = 0, den = 0;
                    for (int t = et[t2]; t < et[t2 + 1]; ++t)
                        for (int p = ep[p2]; p < ep[p2 + 1]; ++p) {
                            const double w = omega[t];
                            const double v = b.at(k, t, p, c) * w;
                            num += quadrature ? v * v : v;
                            den += w;
                        }
                    out.push_back(float((quadrature ? std::sqrt(num) : num) / den));
                }
    return out;
}

// 16-bit log codes of `values` over the ten decades below their maximum.
std::vector<std::uint16_t> log_codes(const std::vector<float>& values, LogCodec& codec) {
    float max_v = 0;
    for (float v : values)
        if (std::isfinite(v)) max_v = std::max(max_v, v);
    codec.hi = max_v > 0 ? std::log10(double(max_v)) : 0.0;
    codec.lo = codec.hi - kLogDecades;
    std::vector<std::uint16_t> codes;
    codes.reserve(values.size());
    for (float v : values)
        codes.push_back(codec.encode(v));
    return codes;
}

// Σ_j f_j Ω⊥_j per block and channel (NaN bins, a side a model does not support, skipped; a block
// of NaN only has no albedo), or with `quadrature` √Σ (se_j Ω⊥_j)² — the reference's standard
// error with the bins taken as independent (a slight overestimate: a particle lands in one bin).
std::vector<std::optional<std::array<double, 3>>> albedos(const BinBlocks& b, bool quadrature) {
    std::vector<std::optional<std::array<double, 3>>> out;
    const std::vector<double> omega = omega_perp_rows(b.T, b.P, b.unfolded);
    for (std::size_t k = 0; k < b.blocks(); ++k) {
        std::array<double, 3> a = {0, 0, 0};
        bool finite = false;
        for (std::size_t t = 0; t < b.T; ++t)
            for (std::size_t p = 0; p < b.P; ++p)
                for (std::size_t c = 0; c < 3; ++c) {
                    const float f = b.at(k, t, p, c);
                    if (std::isnan(f)) continue;
                    finite = true;
                    const double v = f * omega[t];
                    a[c] += quadrature ? v * v : v;
                }
        if (quadrature)
            for (double& v : a)
                v = std::sqrt(v);
        out.push_back(finite ? std::optional(a) : std::nullopt);
    }
    return out;
}

// The polarization view's maps as 16-bit codes, [incidence, side, merged θ bin, merged φ bin,
// channel] (docs/explorer.md, "Data"): the degree of polarization and its standard error over
// [0, 1] (code round(65534 · value), 65535 where the bin has no light), the angle of linear
// polarization over [−90°, 90°] (code round(65534 · (angle + 90°) / 180°)).
struct Polarization {
    std::vector<std::uint16_t> dop, dop_se, aolp;
};

constexpr std::uint16_t kCodeNone = 65535;

std::uint16_t unit_code(double v) {
    return std::isfinite(v) ? std::uint16_t(std::lround(std::clamp(v, 0.0, 1.0) * 65534.0))
                            : kCodeNone;
}

// From configs/<id>/reference_stokes.lza ([quantity (S, se), incidence, side, component, θ, φ,
// channel], docs/formats.md) and the reference's merged f and se (the first I · D blocks of
// `merged`, `merged_se`): the Stokes vectors are merged as f is (Ω⊥-weighted averages: the Stokes
// vectors of incoherent light add), their standard errors in quadrature, then turned into the
// degree and angle of polarization (core/stokes.h).
Polarization encode_polarization(const fs::path& dir, std::size_t I, std::size_t D, std::size_t T,
                                 std::size_t P, bool unfolded, const std::vector<int>& et,
                                 const std::vector<int>& ep, const std::vector<float>& merged,
                                 const std::vector<float>& merged_se) {
    const NpyFloat32 st = read_study_array(dir, "reference_stokes");
    if (st.shape != std::vector<std::size_t>{2, I, D, 3, T, P, 3})
        throw InputError(study_array_path(dir, "reference_stokes").string(), "shape",
                         fmt::format("[{}]: expected [2, incidences {}, sides {}, 3, θ {}, φ {}, "
                                     "3] from config.json and study.json",
                                     fmt::join(st.shape, ", "), I, D, T, P));
    const std::size_t half = st.data.size() / 2;
    const std::vector<float> values(st.data.begin(), st.data.begin() + std::ptrdiff_t(half));
    const std::vector<float> errors(st.data.begin() + std::ptrdiff_t(half), st.data.end());
    const std::vector<float> s = merge_bins(BinBlocks{values, T, P, unfolded}, et, ep, false);
    const std::vector<float> s_se = merge_bins(BinBlocks{errors, T, P, unfolded}, et, ep, true);
    const std::size_t cells = (et.size() - 1) * (ep.size() - 1) * 3;  // one block, merged
    Polarization out;
    for (std::size_t b = 0; b < I * D; ++b)
        for (std::size_t x = 0; x < cells; ++x) {
            std::array<double, 4> v{merged[b * cells + x]}, e{};
            if (!merged_se.empty()) e[0] = merged_se[b * cells + x];
            for (std::size_t k = 0; k < 3; ++k) {
                v[k + 1] = s[(b * 3 + k) * cells + x];
                e[k + 1] = s_se[(b * 3 + k) * cells + x];
            }
            const StokesPolarization p = stokes_polarization(v, e);
            out.dop.push_back(unit_code(p.dop));
            out.dop_se.push_back(unit_code(p.dop_se));
            out.aolp.push_back(unit_code((p.aolp_deg + 90.0) / 180.0));
        }
    return out;
}

struct ConfigData {
    std::string script;      ///< explorer/data/<id>.js
    json albedo, albedo_se;  ///< for the index
};

// Reads one configuration and encodes what the page draws (docs/explorer.md, "Data").
ConfigData encode_configuration(const fs::path& dir, const std::string& id,
                                const std::vector<double>& study_theta_i, int n_theta, int n_phi,
                                json& entry) {
    const fs::path cfg_path = dir / "config.json";
    const json cfg = read_json(cfg_path, "the configuration");
    const auto sources = field<std::vector<std::string>>(cfg, "sources", cfg_path);
    const auto sides = field<std::vector<std::string>>(cfg, "sides", cfg_path);
    // An unfolded configuration (config.json → phi_i, docs/formats.md): its own incidences, on
    // twice the φ bins over [0°, 360°).
    const bool unfolded = cfg.contains("phi_i");
    const std::vector<double> theta_i =
        unfolded ? field<std::vector<double>>(cfg, "theta_i", cfg_path) : study_theta_i;
    const std::vector<double> phi_i = unfolded ? field<std::vector<double>>(cfg, "phi_i", cfg_path)
                                               : std::vector<double>(theta_i.size(), 0.0);
    if (phi_i.size() != theta_i.size())
        throw InputError(
            cfg_path.string(), "/phi_i",
            fmt::format("{} azimuths for {} incidences (theta_i)", phi_i.size(), theta_i.size()));
    if (unfolded)
        for (std::size_t i = 0; i < theta_i.size(); ++i) {
            check_incidence(theta_i[i], cfg_path.string(), "/theta_i");
            if (!(phi_i[i] >= 0 && phi_i[i] <= 360))  // NaN too
                throw InputError(cfg_path.string(), "/phi_i",
                                 fmt::format("{} degrees is outside [0, 360]", phi_i[i]));
        }
    // A spectral reference's channels are linear sRGB under D65 over its range (docs/formats.md).
    if (cfg.contains("spectral") && cfg["spectral"].is_object())
        entry["spectral"] = cfg["spectral"];
    if (unfolded) {
        entry["incidences"] = json::array();
        for (std::size_t i = 0; i < theta_i.size(); ++i)
            entry["incidences"].push_back({theta_i[i], phi_i[i]});
    }
    const std::size_t S = sources.size(), I = theta_i.size(), D = sides.size(), T = n_theta,
                      P = unfolded ? 2 * std::size_t(n_phi) : std::size_t(n_phi);
    // config.json's "tables" is null in a study run with --tables none: nothing to draw.
    if (cfg.contains("tables") && cfg["tables"].is_null())
        throw InputError(cfg_path.string(), "tables",
                         "none: the study was run with --tables none, which keeps no tables for "
                         "the page to draw (run it again with --tables half or full)");
    const NpyFloat32 tab = read_study_array(dir, "tables");
    if (tab.shape != std::vector<std::size_t>{S, I, D, T, P, 3})
        throw InputError(study_array_path(dir, "tables").string(), "shape",
                         fmt::format("[{}]: expected [sources {}, incidences {}, sides {}, θ {}, φ "
                                     "{}, 3] from config.json and study.json",
                                     fmt::format("{}", fmt::join(tab.shape, ", ")), S, I, D, T, P));
    NpyFloat32 se;
    const bool has_se = has_study_array(dir, "reference_se");
    if (has_se) {
        se = read_study_array(dir, "reference_se");
        if (se.shape != std::vector<std::size_t>{I, D, T, P, 3})
            throw InputError(study_array_path(dir, "reference_se").string(), "shape",
                             fmt::format("expected [{}, {}, {}, {}, 3]", I, D, T, P));
    }
    const BinBlocks f{tab.data, T, P, unfolded}, f_se{se.data, T, P, unfolded};

    // 1. The incident-plane slice at full resolution, float32 [source, incidence, side, 2T, 3]
    //    (unfolded: the plane of each incidence, φ = φi and φi + 180°).
    const std::vector<float> slice = incident_plane(f, phi_i, D);
    const std::vector<float> slice_se =
        has_se ? incident_plane(f_se, phi_i, D) : std::vector<float>();

    // 2. Albedos of every source, and the reference's standard error.
    const auto a = albedos(f, false);
    const auto a_se = has_se ? albedos(f_se, true) : decltype(a)();
    auto rgb = [](const std::optional<std::array<double, 3>>& v) {
        return v ? json{(*v)[0], (*v)[1], (*v)[2]} : json(nullptr);
    };
    json albedo = json::object(), albedo_se = json::object();
    for (std::size_t s = 0; s < S; ++s)
        for (std::size_t d = 0; d < D; ++d)
            for (std::size_t i = 0; i < I; ++i) {
                albedo[sources[s]][sides[d]].push_back(rgb(a[(s * I + i) * D + d]));
                if (s == 0 && has_se) albedo_se[sides[d]].push_back(rgb(a_se[i * D + d]));
            }

    // 3. The hemisphere for the iso-value maps, and the reference's se for the significance of
    //    differences: bins merged to at most ~45 × 45, then 16-bit log codes.
    const int kt = (int(T) + 44) / 45, kp = (int(P) + 44) / 45;
    const std::vector<int> et = merged_edges(int(T), kt), ep = merged_edges(int(P), kp);
    LogCodec codec, se_codec;
    const std::vector<float> merged = merge_bins(f, et, ep, false);
    const std::vector<float> merged_se =
        has_se ? merge_bins(f_se, et, ep, true) : std::vector<float>();
    const std::vector<std::uint16_t> codes = log_codes(merged, codec);
    const std::vector<std::uint16_t> se_codes =
        has_se ? log_codes(merged_se, se_codec) : std::vector<std::uint16_t>();
    const std::size_t T2 = et.size() - 1, P2 = ep.size() - 1;

    // 4. The reference's polarization for unpolarized light (reference_stokes.lza, when the study
    //    stored it): its degree and the angle of its linear part on the same merged bins.
    const std::optional<Polarization> polarization =
        has_study_array(dir, "reference_stokes")
            ? std::optional(
                  encode_polarization(dir, I, D, T, P, unfolded, et, ep, merged, merged_se))
            : std::nullopt;
    std::vector<double> theta_edges, phi_edges;
    for (int e : et)
        theta_edges.push_back(90.0 * e / T);
    for (int e : ep)
        phi_edges.push_back((unfolded ? 360.0 : 180.0) * e / double(P));

    // Support and reasons: from config.json, else derived from the NaNs of the tables.
    json supported = cfg.value("supported", json::object());
    for (std::size_t s = 1; s < S; ++s)
        if (!supported.contains(sources[s])) {
            json m = json::object();
            for (std::size_t d = 0; d < D; ++d)
                m[sides[d]] = !albedo[sources[s]][sides[d]][0].is_null();
            supported[sources[s]] = m;
        }
    entry["supported"] = supported;
    // The reference's energy budget per incidence (config.json → energy, when present): what the
    // albedo view shows next to the albedos, so a reader sees how much energy the reference itself
    // drops to single-scattering microsurfaces or absorbs, and a model that does not cannot match.
    if (cfg.contains("energy") && cfg["energy"].is_array()) {
        json budget = json::object();
        for (const char* term : {"lost_microsurface", "absorbed_medium", "absorbed_base"}) {
            json per_incidence = json::array();
            for (std::size_t i = 0; i < theta_i.size(); ++i) {
                json v = nullptr;
                for (const json& e : cfg["energy"])
                    if (e.contains("theta_i") && e["theta_i"].is_number() &&
                        e["theta_i"].get<double>() == theta_i[i] &&
                        e.value("phi_i", 0.0) == phi_i[i] && e.contains(term))
                        v = e[term];
                per_incidence.push_back(v);
            }
            budget[term] = per_incidence;
        }
        entry["budget"] = budget;
    }
    entry["sources"] = sources;
    entry["sides"] = sides;

    // Sphere renderings (optional, a later issue writes them): configs/<id>/renders/<source>.png,
    // the reference as reference.png or random-walk.png (what `lamina render --compare` names it),
    // and the relative RMSE of each model's image from renders/errors.csv when present.
    json renders = json::object();
    for (const std::string& s : sources) {
        const std::vector<std::string> names =
            s == "reference" ? std::vector<std::string>{"reference", "random-walk"}
                             : std::vector<std::string>{s};
        for (const std::string& n : names)
            if (fs::exists(dir / "renders" / (n + ".png"))) {
                renders[s] = fmt::format("configs/{}/renders/{}.png", id, n);
                break;
            }
    }
    entry["renders"] = renders;
    json render_errors = json::object();
    if (std::istringstream err(digest_bytes(dir / "renders" / "errors.csv")); err) {
        std::string line;
        std::getline(err, line);  // model,rel_rmse,seconds
        while (std::getline(err, line)) {
            const std::vector<std::string> v = split_csv_line(line);
            if (v.size() >= 2 && !v[1].empty()) render_errors[v[0]] = v[1];
        }
    }
    entry["render_errors"] = render_errors;

    // Every array packed (core/packed_array.h: lossless, deflate; the page inflates it with the
    // browser's DecompressionStream), then base64.
    const std::size_t X = 2 * T;
    auto packed = [](const auto& v, std::size_t n) {
        const std::string p = pack_elements(v.data(), v.size(), sizeof(v[0]), n, 3);
        return base64(p.data(), p.size());
    };
    json data = {
        {"id", id},
        {"sources", sources},
        {"sides", sides},
        {"packed", true},
        {"slice", packed(slice, X)},
        {"slice_se", has_se ? json(packed(slice_se, X)) : json(nullptr)},
        {"hemi",
         {{"n_theta", T2},
          {"n_phi", P2},
          {"theta_edges", theta_edges},
          {"phi_edges", phi_edges},
          {"lo", codec.lo},
          {"hi", codec.hi},
          {"codes", packed(codes, P2)},
          {"se_lo", se_codec.lo},
          {"se_hi", se_codec.hi},
          {"se_codes", has_se ? json(packed(se_codes, P2)) : json(nullptr)}}},
    };
    if (unfolded) data["hemi"]["unfolded"] = true;  // φ edges over [0°, 360°)
    // lamina-1's GLSL states for the live spheres (config.json → lamina1_gpu, docs/formats.md):
    // the file's float32 as base64, with its layout.
    if (cfg.contains("lamina1_gpu") && cfg["lamina1_gpu"].is_object()) {
        const json& g = cfg["lamina1_gpu"];
        const fs::path file = dir / field<std::string>(g, "file", cfg_path);
        std::error_code ec;
        if (!fs::exists(file, ec))
            throw InputError(file.string(), "", "not found (config.json → lamina1_gpu names it)");
        const std::string bytes =
            read_regular_file_bounded(file, kMaxTableFileBytes, "lamina-1's states");
        const auto n_state = field<std::size_t>(g, "state", cfg_path);
        const auto head = field<std::size_t>(g, "head", cfg_path);
        // A slab's bins at the state's end (`tail`; absent where the study wrote none).
        const std::size_t tail = g.contains("tail") ? field<std::size_t>(g, "tail", cfg_path) : 0;
        const json variants = field<json>(g, "variants", cfg_path);
        if (tail > n_state || head > n_state - tail ||
            bytes.size() != 4 * (n_state + (head + tail) * variants.size()))
            throw InputError(
                file.string(), "size",
                fmt::format("{} bytes: expected 4 × ({} + ({} + {}) × {}) from config.json",
                            bytes.size(), n_state, head, tail, variants.size()));
        data["lamina1"] = {{"state", n_state},
                           {"head", head},
                           {"tail", tail},
                           {"variants", variants},
                           {"floats", base64(bytes.data(), bytes.size())}};
    }
    if (polarization)
        data["polarization"] = {{"dop", packed(polarization->dop, P2)},
                                {"dop_se", packed(polarization->dop_se, P2)},
                                {"aolp", packed(polarization->aolp, P2)}};
    ConfigData out;
    out.script = fmt::format("(window.LAMINA_DATA = window.LAMINA_DATA || {{}})[{}] = {};\n",
                             json(id).dump(), data.dump());
    out.albedo = albedo;
    out.albedo_se = albedo_se;
    return out;
}

// The GLSL the live spheres load (web/spheres.js), as strings a file:// page can read:
// window.LAMINA_GLSL = {lamina1, laminaCoat, laminaCoatTable (the 32 × 577 integers)}.
std::string glsl_script() {
    std::vector<int> table;
    std::istringstream in{std::string(assets::lamina_coat_tables_csv())};
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        for (const std::string& v : split_csv_line(line))
            table.push_back(std::stoi(v));
    }
    const json glsl = {{"lamina1", std::string(assets::lamina1_glsl())},
                       {"laminaCoat", std::string(assets::lamina_coat_glsl())},
                       {"laminaCoatTable", table}};
    return "window.LAMINA_GLSL = " + glsl.dump() + ";\n";
}

// Plotly as embedded at build time or, when `make deps` installed it after the build was
// configured, as installed in the source tree.
std::string plotly_bundle() {
    if (!assets::plotly_js().empty()) return std::string(assets::plotly_js());
    std::ifstream in(LAMINA_PLOTLY_INSTALLED, std::ios::binary);
    std::stringstream ss;
    if (in) ss << in.rdbuf();
    if (ss.str().empty())
        throw InputError(LAMINA_PLOTLY_INSTALLED, "",
                         "Plotly is not installed, nor embedded in this lamina: run `make deps` "
                         "(npm ci), then rebuild");
    return ss.str();
}

// What a configuration's page data is encoded from: its files (config.json, the tables, the
// renderings' names and errors.csv), its index entry, the study's axes and this lamina.
std::string inputs_digest(const fs::path& dir, const json& entry,
                          const std::vector<double>& theta_i, int n_theta, int n_phi) {
    std::uint64_t h = fnv1a(fmt::format("explorer data v2 | lamina {} | {} | {} | {}x{}", kVersion,
                                        entry.dump(), fmt::join(theta_i, ","), n_theta, n_phi));
    for (const char* name :
         {"config.json", "lamina1_gpu.f32", "tables.lza", "reference_se.lza", "tables.npy",
          "reference_se.npy", "reference_stokes.lza", "renders/errors.csv"}) {
        std::error_code ec;
        const bool there = fs::exists(dir / name, ec);
        h = fnv1a(fmt::format("| {} {} |", name, there), h);
        h = fnv1a(there ? digest_bytes(dir / name) : std::string(), h);
    }
    std::error_code ec;
    std::vector<std::string> renders;
    for (const auto& e : fs::directory_iterator(dir / "renders", ec))
        if (e.path().extension() == ".png") renders.push_back(e.path().filename().string());
    std::sort(renders.begin(), renders.end());
    return digest_hex(fnv1a(fmt::format("{}", fmt::join(renders, ",")), h));
}

}  // namespace

namespace {
ExplorerSummary write_explorer_unchecked(const fs::path& study_dir);
}  // namespace

ExplorerSummary write_explorer(const fs::path& study_dir) {
    // The study's files are read field by field with their names where a value is checked; a
    // value of the wrong type anywhere else is still the folder's damage, not lamina's error.
    try {
        return write_explorer_unchecked(study_dir);
    } catch (const json::exception& e) {
        throw InputError(study_dir.string(), "",
                         fmt::format("a file of this study folder holds a value of the wrong "
                                     "type ({}): damaged, or written by another program?",
                                     json_exception_text(e)));
    }
}

namespace {
ExplorerSummary write_explorer_unchecked(const fs::path& study_dir) {
    const fs::path study_path = study_dir / "study.json";
    if (!fs::exists(study_path))
        throw InputError(study_path.string(), "",
                         "not found: expected a study directory written by `lamina study` or "
                         "`lamina compare`");
    const json study = read_json(study_path, "the study's description");
    // The page draws from what it is given: the incidences in range, the model names strings.
    auto theta_i = field<std::vector<double>>(study, "theta_i", study_path);
    check_incidence_list(theta_i, study_path.string(), "/theta_i");
    if (study.contains("models")) {
        const auto names = field<std::vector<std::string>>(study, "models", study_path);
        for (const std::string& name : names)
            if (name.empty())
                throw InputError(study_path.string(), "/models", "a model name is empty");
    }
    const json grid = field<json>(study, "grid", study_path);
    // Counts in range (they size every array below); read wide so that 1e18 is not wrapped.
    const HemisphereGrid checked_grid = HemisphereGrid::checked(
        field<long long>(grid, "n_theta", study_path), field<long long>(grid, "n_phi", study_path),
        study_path.string(), "/grid");
    const int n_theta = checked_grid.n_theta(), n_phi = checked_grid.n_phi();
    const json configurations = field<json>(study, "configurations", study_path);
    const std::string plotly = plotly_bundle();

    // Stage everything first: a failure leaves the previous page untouched.
    StagedOutput data_out(study_dir / "explorer" / "data");
    ExplorerSummary summary;
    json index = {{"study", json::object()}, {"configs", json::array()}};
    for (const char* key : {"preset", "particles", "seed", "lamina_version", "models",
                            "model_groups", "grid", "microsurface", "polarization", "physics"})
        if (study.contains(key)) index["study"][key] = study[key];
    index["study"]["theta_i"] = theta_i;
    // The page's title: the study folder's name (`out/study-quick/` → study-quick).
    fs::path folder = fs::absolute(study_dir).lexically_normal();
    if (folder.filename().empty()) folder = folder.parent_path();
    index["study"]["name"] = folder.filename().string();
    // A configuration whose inputs (its files, the study's axes, this lamina) are those the last
    // page was drawn from is not encoded again: its index entry comes from the stamps.
    const fs::path stamps_path = study_dir / "explorer" / "data" / ".inputs.json";
    json stamps = json::object(), new_stamps = json::object();
    if (const std::string text = digest_bytes(stamps_path); !text.empty()) {
        try {
            stamps = json::parse(text);
        } catch (const std::exception&) {
            stamps = json::object();
        }
    }
    ConfigIncidences unfolded;
    // Each configuration's stamp first, then the ones to encode again side by side over the
    // threads (each reads its own files), then their scripts and index entries in order.
    struct Item {
        std::string id, digest;
        json entry;
        bool unchanged = false;
    };
    std::vector<Item> items;
    for (const json& c : configurations) {
        Item item;
        item.id = field<std::string>(c, "id", study_path);
        const std::string& id = item.id;
        if (c.contains("incidences") && c["incidences"].is_array())
            for (const json& inc : c["incidences"])
                if (inc.is_array() && inc.size() == 2 && inc[0].is_number() && inc[1].is_number())
                    unfolded[id].push_back({inc[0].get<double>(), inc[1].get<double>()});
        item.entry = {{"id", id},
                      {"category", c.value("category", "custom")},
                      {"parameters", c.value("parameters", json::object())}};
        item.digest =
            inputs_digest(study_dir / "configs" / id, item.entry, theta_i, n_theta, n_phi);
        // The data file must be the one written then (its digest in the stamp): a truncated or
        // edited one is encoded again.
        const fs::path script = study_dir / "explorer" / "data" / (id + ".js");
        if (stamps.contains(id) && stamps[id].is_object() &&
            stamps[id].value("digest", "") == item.digest && stamps[id].contains("entry") &&
            fs::exists(script) &&
            stamps[id].value("script", "") == digest_hex(fnv1a(digest_bytes(script)))) {
            item.entry = stamps[id]["entry"];
            item.unchanged = true;
            summary.data_bytes += fs::file_size(script);
            ++summary.unchanged;
        }
        items.push_back(std::move(item));
    }
    std::vector<std::optional<ConfigData>> encoded(items.size());
    std::vector<std::exception_ptr> failures(items.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (long k = 0; k < long(items.size()); ++k) {
        Item& item = items[std::size_t(k)];
        if (item.unchanged) continue;
        try {
            encoded[std::size_t(k)] = encode_configuration(study_dir / "configs" / item.id, item.id,
                                                           theta_i, n_theta, n_phi, item.entry);
        } catch (...) {
            failures[std::size_t(k)] = std::current_exception();
        }
    }
    for (std::size_t k = 0; k < items.size(); ++k) {
        if (failures[k]) std::rethrow_exception(failures[k]);
        Item& item = items[k];
        std::string script_digest = items[k].unchanged ? stamps[item.id].value("script", "") : "";
        if (encoded[k]) {
            const ConfigData& d = *encoded[k];
            item.entry["albedo"] = d.albedo;
            item.entry["albedo_se"] = d.albedo_se;
            summary.data_bytes += d.script.size();
            data_out.add_if_changed(item.id + ".js", d.script);
            script_digest = digest_hex(fnv1a(d.script));
        }
        new_stamps[item.id] = {
            {"digest", item.digest}, {"entry", item.entry}, {"script", script_digest}};
        index["configs"].push_back(item.entry);
        ++summary.configurations;
    }
    index["metrics"] = read_metrics(study_dir / "metrics.csv", theta_i, unfolded);
    index["palette"] = json::parse(assets::model_colors_json());
    const std::string index_js = "window.LAMINA_INDEX = " + index.dump() + ";\n";
    summary.data_bytes += index_js.size();
    data_out.add_if_changed("index.js", index_js);
    data_out.add_if_changed(".inputs.json", new_stamps.dump() + "\n");

    StagedOutput page_out(study_dir / "explorer");
    page_out.add_if_changed("plotly.min.js", plotly);
    page_out.add_if_changed("explorer.js", assets::explorer_js());
    page_out.add_if_changed("colour.js", assets::colour_js());
    page_out.add_if_changed("explorer.css", assets::explorer_css());
    page_out.add_if_changed("spheres.js", assets::spheres_js());
    page_out.add_if_changed("glsl.js", glsl_script());
    StagedOutput root_out(study_dir);
    root_out.add_if_changed("index.html", assets::explorer_html());
    data_out.commit();
    page_out.commit();
    root_out.commit();
    return summary;
}
}  // namespace

}  // namespace lamina
