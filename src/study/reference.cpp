#include "study/reference.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/packed_array.h"
#include "lamina/version.h"
#include "reference_source_digest.h"
#include "simulator/mueller.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace lamina {

namespace {

// v2 packs the data (core/packed_array.h): f as float32, losslessly (the metrics are computed from
// it), and its standard errors as float16 — an estimate whose own relative uncertainty is of order
// 1/√(particles in the bin), far above float16's 2⁻¹¹ —: 40% of v1's bytes; v1 pieces, f and
// se stored raw as float32, are still read.
constexpr const char* kMagic = "lamina-reference-piece v2\n";
constexpr const char* kMagicV1 = "lamina-reference-piece v1\n";

// A rough dielectric interface somewhere in the stack: its refraction masking shapes the table.
bool has_rough_dielectric(const Stack& stack) {
    for (const Layer& layer : stack.layers)
        if (layer.interface.type == InterfaceType::Dielectric && layer.interface.alpha > 0)
            return true;
    return false;
}

nlohmann::json metrics_json(const LobeMetrics& m) {
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    return {{"misplaced_energy", num(m.misplaced_energy)},
            {"misplaced_floor", m.misplaced_floor},
            {"albedo_ref", m.albedo_ref},
            {"albedo_model", m.albedo_model},
            {"albedo_error", num(m.albedo_error)},
            {"rmse", m.rmse},
            {"log_rmse", m.log_rmse}};
}

LobeMetrics metrics_from_json(const nlohmann::json& j) {
    auto num = [](const nlohmann::json& v) { return v.is_null() ? NAN : v.get<double>(); };
    LobeMetrics m;
    m.misplaced_energy = num(j.at("misplaced_energy"));
    m.albedo_ref = j.at("albedo_ref").get<double>();
    m.albedo_model = j.at("albedo_model").get<double>();
    m.albedo_error = num(j.at("albedo_error"));
    m.rmse = j.at("rmse").get<double>();
    m.log_rmse = j.at("log_rmse").get<double>();
    if (j.contains("misplaced_floor")) {
        m.misplaced_floor = j.at("misplaced_floor").get<double>();
    } else {
        // A piece stored before misplaced_floor existed: the same Σ|b − a|Ω⊥ (halved) over the
        // floored energy. With a's energy 0, |b − a| = b (tallies are ≥ 0), whose energy is
        // albedo_model (not halved by noise_floor), so Σ|b − a|Ω⊥ / 2 = albedo_model / 2.
        m.misplaced_floor =
            m.albedo_ref > 0 && std::isfinite(m.misplaced_energy)
                ? m.misplaced_energy * m.albedo_ref / std::max(m.albedo_ref, kMisplacedFloorEnergy)
                : m.albedo_model / 2 / kMisplacedFloorEnergy;
    }
    return m;
}

// Layout: magic line, one line of JSON (key, budget, floor, sizes), then the data as
// [block, θ bin, φ bin, channel]. v2: f of each side present (float32, packed; "f_packed" bytes),
// then se of each side (float16, packed; "se_packed" bytes where Stokes components follow), then
// with Stokes components ("stokes_packed" bytes) S1, S2, S3 of each side (float32, packed) and
// their standard errors (float16, packed). v1: for each side, f then se, raw float32.
std::string serialize(const ReferenceKey& key, const ReferencePiece& p) {
    nlohmann::json meta;
    meta["key"] = key.canonical();
    meta["has_transmission"] = p.has_transmission;
    meta["bins"] = key.grid().size();
    meta["seconds"] = p.seconds;
    nlohmann::json budget;
    for (int t = 0; t < kBudgetTerms; ++t)
        budget[kBudgetTermNames[t]] = {p.budget.term[t][0], p.budget.term[t][1],
                                       p.budget.term[t][2]};
    budget["reflected_se"] = {p.budget.reflected_se[0], p.budget.reflected_se[1],
                              p.budget.reflected_se[2]};
    budget["transmitted_se"] = {p.budget.transmitted_se[0], p.budget.transmitted_se[1],
                                p.budget.transmitted_se[2]};
    meta["budget"] = budget;
    for (int side = 0; side < 2; ++side)
        for (int c = 0; c < 3; ++c)
            meta["floor"][side][c] = metrics_json(p.floor[side][c]);
    std::vector<float> f;
    std::vector<std::uint16_t> se;
    for (int side = 0; side < (p.has_transmission ? 2 : 1); ++side)
        for (std::size_t j = 0; j < p.f[side].size(); ++j)
            for (int c = 0; c < 3; ++c) {
                f.push_back(float(p.f[side][j][c]));
                se.push_back(float_to_half(float(p.se[side][j][c])));
            }
    const std::size_t n_phi = std::size_t(key.grid().n_phi());
    const std::string f_packed = pack_elements(f.data(), f.size(), sizeof(float), n_phi, 3);
    const std::string se_packed =
        pack_elements(se.data(), se.size(), sizeof(std::uint16_t), n_phi, 3);
    meta["f_packed"] = f_packed.size();
    if (p.stokes[0].empty()) return kMagic + meta.dump() + "\n" + f_packed + se_packed;
    // The Stokes components as [side, component, θ bin, φ bin, channel]: S as float32, their
    // standard errors as float16, after se.
    std::vector<float> stokes;
    std::vector<std::uint16_t> stokes_se;
    for (int side = 0; side < (p.has_transmission ? 2 : 1); ++side)
        for (std::size_t k = 0; k < 3; ++k)
            for (std::size_t j = 0; j < p.stokes[side].size(); ++j)
                for (int c = 0; c < 3; ++c) {
                    stokes.push_back(float(p.stokes[side][j][k][c]));
                    stokes_se.push_back(float_to_half(float(p.stokes_se[side][j][k][c])));
                }
    const std::string stokes_packed =
        pack_elements(stokes.data(), stokes.size(), sizeof(float), n_phi, 3);
    meta["se_packed"] = se_packed.size();
    meta["stokes_packed"] = stokes_packed.size();
    return kMagic + meta.dump() + "\n" + f_packed + se_packed + stokes_packed +
           pack_elements(stokes_se.data(), stokes_se.size(), sizeof(std::uint16_t), n_phi, 3);
}

bool deserialize(const std::string& bytes, const ReferenceKey& key, ReferencePiece& p) {
    const std::size_t magic_len = std::strlen(kMagic);
    const bool packed = bytes.compare(0, magic_len, kMagic) == 0;
    if (!packed && bytes.compare(0, magic_len, kMagicV1) != 0) return false;
    const std::size_t eol = bytes.find('\n', magic_len);
    if (eol == std::string::npos) return false;
    nlohmann::json meta;
    try {
        meta = nlohmann::json::parse(bytes.substr(magic_len, eol - magic_len));
        if (meta.at("key").get<std::string>() != key.canonical()) return false;
        if (meta.at("bins").get<std::size_t>() != key.grid().size()) return false;
        p.has_transmission = meta.at("has_transmission").get<bool>();
        p.seconds = meta.at("seconds").get<double>();
        const auto& budget = meta.at("budget");
        for (int t = 0; t < kBudgetTerms; ++t)
            for (int c = 0; c < 3; ++c)
                p.budget.term[t][c] = budget.at(kBudgetTermNames[t]).at(c).get<double>();
        for (int c = 0; c < 3; ++c) {
            p.budget.reflected_se[c] = budget.at("reflected_se").at(c).get<double>();
            p.budget.transmitted_se[c] = budget.at("transmitted_se").at(c).get<double>();
        }
        for (int side = 0; side < 2; ++side)
            for (int c = 0; c < 3; ++c)
                p.floor[side][c] = metrics_from_json(meta.at("floor").at(side).at(c));
    } catch (const std::exception&) {
        return false;
    }
    // The header's numbers as serialize writes them, else a damaged piece (computed again): the
    // energy budget finite and of the order of 1 (its terms are unbiased estimates, a few may be
    // slightly negative; a spectral run's sRGB may leave [0, 1]), standard errors and the noise
    // floor's energies and norms never negative, every value within the tables' bound (a metric
    // may be NaN: not defined).
    auto order_one = [](double x) { return std::abs(x) <= 10; };
    auto bounded = [](double x, bool nonnegative) {
        return std::isnan(x) || (std::abs(x) <= kMaxBinValue && !(nonnegative && x < 0));
    };
    bool sane = std::isfinite(p.seconds) && p.seconds >= 0;
    for (int c = 0; c < 3; ++c) {
        for (int t = 0; t < kBudgetTerms; ++t)
            sane = sane && order_one(p.budget.term[t][c]);
        sane = sane && order_one(p.budget.reflected_se[c]) && p.budget.reflected_se[c] >= 0 &&
               order_one(p.budget.transmitted_se[c]) && p.budget.transmitted_se[c] >= 0;
        for (int side = 0; side < 2; ++side) {
            const LobeMetrics& m = p.floor[side][c];
            sane = sane && bounded(m.misplaced_energy, true) && bounded(m.misplaced_floor, true) &&
                   bounded(m.albedo_ref, false) && bounded(m.albedo_model, false) &&
                   bounded(m.albedo_error, false) && bounded(m.rmse, true) &&
                   bounded(m.log_rmse, true);
        }
    }
    if (!sane) return false;
    const std::size_t sides = p.has_transmission ? 2 : 1;
    const std::size_t n = key.grid().size();
    const std::size_t expected = sides * 2 * n * 3 * sizeof(float);
    std::vector<float> data(expected / sizeof(float));
    if (packed) {
        // Into v1's order: for each side, f then se.
        const std::size_t values = sides * n * 3;  // of f, and of se
        std::vector<float> f(values);
        std::vector<std::uint16_t> se(values);
        try {
            const std::size_t f_bytes = meta.at("f_packed").get<std::size_t>();
            const std::string_view rest = std::string_view(bytes).substr(eol + 1);
            if (f_bytes > rest.size()) return false;
            // A piece with Stokes components says where se ends; one without ends with se.
            const bool has_stokes = meta.contains("stokes_packed");
            if (key.settings.stokes_tallies && !has_stokes) return false;  // computed again
            const std::size_t se_bytes =
                has_stokes ? meta.at("se_packed").get<std::size_t>() : rest.size() - f_bytes;
            const std::size_t stokes_bytes =
                has_stokes ? meta.at("stokes_packed").get<std::size_t>() : 0;
            if (f_bytes + se_bytes + stokes_bytes > rest.size()) return false;
            const std::size_t n_phi = std::size_t(key.grid().n_phi());
            unpack_elements(rest.substr(0, f_bytes), f.data(), values, sizeof(float), n_phi, 3,
                            key.file_name());
            unpack_elements(rest.substr(f_bytes, se_bytes), se.data(), values,
                            sizeof(std::uint16_t), n_phi, 3, key.file_name());
            if (has_stokes) {
                std::vector<float> stokes(3 * values);
                std::vector<std::uint16_t> stokes_se(3 * values);
                unpack_elements(rest.substr(f_bytes + se_bytes, stokes_bytes), stokes.data(),
                                stokes.size(), sizeof(float), n_phi, 3, key.file_name());
                unpack_elements(rest.substr(f_bytes + se_bytes + stokes_bytes), stokes_se.data(),
                                stokes_se.size(), sizeof(std::uint16_t), n_phi, 3, key.file_name());
                std::size_t at = 0;
                for (std::size_t side = 0; side < sides; ++side) {
                    p.stokes[side].assign(n, {});
                    p.stokes_se[side].assign(n, {});
                    for (std::size_t k = 0; k < 3; ++k)
                        for (std::size_t j = 0; j < n; ++j)
                            for (int c = 0; c < 3; ++c, ++at) {
                                p.stokes[side][j][k][c] = stokes[at];
                                p.stokes_se[side][j][k][c] = half_to_float(stokes_se[at]);
                            }
                }
            }
        } catch (const std::exception&) {
            return false;  // damaged: computed again
        }
        for (std::size_t side = 0; side < sides; ++side)
            for (std::size_t k = 0; k < n * 3; ++k) {
                data[(2 * side) * n * 3 + k] = f[side * n * 3 + k];
                data[(2 * side + 1) * n * 3 + k] = half_to_float(se[side * n * 3 + k]);
            }
    } else {
        if (key.settings.stokes_tallies) return false;  // v1 pieces have no Stokes components
        if (bytes.size() != eol + 1 + expected) return false;
        std::memcpy(data.data(), bytes.data() + eol + 1, expected);
    }
    std::size_t at = 0;
    for (std::size_t side = 0; side < sides; ++side)
        for (auto* v : {&p.f[side], &p.se[side]}) {
            v->resize(n);
            for (Rgbd& x : *v)
                for (int c = 0; c < 3; ++c)
                    x[c] = data[at++];
        }
    return true;
}

// A piece's bytes; empty (a damaged piece, recomputed) for anything but a regular file within
// the tables' bound.
std::string read_file(const std::filesystem::path& path) {
    return read_cache_file(path, kMaxTableFileBytes).value_or(std::string());
}

}  // namespace

std::string ReferenceKey::canonical() const {
    const TransportSettings& t = settings.transport;
    const bool masking_said = t.microsurface == Microsurface::Single &&
                              t.transmission_masking == TransmissionMasking::Smith &&
                              has_rough_dielectric(stack);
    return fmt::format(
        "lamina {} | code {} | config {} | stack {} | theta_i {} | particles {} | seed {} | "
        "grid {} | kernel {}{}{}",
        kVersion, kReferenceSourceDigest, config_id, stack_to_json(stack).dump(), theta_i_deg(),
        settings.particles, settings.seed, settings.grid.to_string(),
        kernel_description(traced_kernel(settings, stack)), settings_key_text(settings),
        masking_said ? " | transmission masking smith" : "");
}

std::string ReferenceKey::file_name() const {
    const std::string phi = phi_i_deg() != 0 ? fmt::format("-phi{}", phi_i_deg()) : "";
    return fmt::format("theta{}{}-n{}-s{}-{:016x}.bin", theta_i_deg(), phi, settings.particles,
                       settings.seed, fnv1a(canonical()));
}

const char* reference_code_digest() {
    return kReferenceSourceDigest;
}

ReferenceKey reference_key(const std::string& config_id, const Stack& stack, double theta_i_deg,
                           const SimulationSettings& reference) {
    ReferenceKey key{config_id, stack, reference};
    key.settings.theta_i_deg = {theta_i_deg};
    key.settings.threads = 0;
    key.settings.first_particle = 0;
    return key;
}

ReferenceKey reference_key(const std::string& config_id, const Stack& stack, double theta_i_deg,
                           const SimulationSettings& reference, double phi_i_deg) {
    ReferenceKey key = reference_key(config_id, stack, theta_i_deg, reference);
    key.settings.phi_i_deg = phi_i_deg;  // a Key::Tail setting: said only where it is not 0
    return key;
}

std::uint64_t second_half_seed(std::uint64_t seed) {
    // A fixed odd offset (the 64-bit golden ratio): a different key for Philox, never equal.
    return seed + 0x9e3779b97f4a7c15ull;
}

std::optional<ReferencePiece> load_reference_piece(const std::filesystem::path& cache_dir,
                                                   const ReferenceKey& key) {
    const std::filesystem::path file = cache_dir / key.config_id / key.file_name();
    ReferencePiece piece;
    if (std::filesystem::exists(file) && deserialize(read_file(file), key, piece)) return piece;
    return std::nullopt;
}

std::string compute_reference_piece(const ReferenceKey& key, int threads,
                                    const std::function<void(std::uint64_t)>& on_progress) {
    // Two halves with different seeds; the same stream (the incidence) in each.
    const std::uint64_t particles = key.settings.particles;
    SimulationSettings s = key.settings;
    s.threads = threads;
    s.particles = (particles + 1) / 2;
    const SimulationResult a = simulate(key.stack, s, on_progress);
    const std::uint64_t n_a = s.particles;
    s.particles = particles - n_a;
    s.seed = second_half_seed(key.settings.seed);
    const SimulationResult b = simulate(key.stack, s, on_progress);
    const std::uint64_t n_b = s.particles;
    const double wa = double(n_a) / double(particles), wb = double(n_b) / double(particles);

    const HemisphereGrid grid = key.grid();
    ReferencePiece piece;
    piece.has_transmission = a.table.has_transmission;
    piece.seconds = a.seconds + b.seconds;
    for (int side = 0; side < (piece.has_transmission ? 2 : 1); ++side) {
        const Side sd = side == 0 ? Side::Reflection : Side::Transmission;
        const BinnedLobe& la = a.table.lobe(0, sd);
        const BinnedLobe& lb = b.table.lobe(0, sd);
        piece.f[side].resize(grid.size());
        piece.se[side].resize(grid.size());
        for (std::size_t j = 0; j < grid.size(); ++j)
            for (int c = 0; c < 3; ++c) {
                piece.f[side][j][c] = wa * la.f[j][c] + wb * lb.f[j][c];
                piece.se[side][j][c] = std::hypot(wa * la.se[j][c], wb * lb.se[j][c]);
            }
        for (int c = 0; c < 3; ++c)
            piece.floor[side][c] = noise_floor(grid, la.f, lb.f, c);
        if (!s.stokes_tallies) continue;
        // The Stokes vectors of the halves (each lit unpolarized), averaged as f.
        piece.stokes[side].resize(grid.size());
        piece.stokes_se[side].resize(grid.size());
        for (std::size_t j = 0; j < grid.size(); ++j) {
            const std::size_t entry = std::size_t(side) * grid.size() + j;
            const double omega = grid.projected_solid_angle(j);
            const BinStokesVector va = unpolarized_stokes(a.sums[0], entry, omega, n_a);
            const BinStokesVector vb = unpolarized_stokes(b.sums[0], entry, omega, n_b);
            for (std::size_t k = 0; k < 3; ++k)
                for (int c = 0; c < 3; ++c) {
                    piece.stokes[side][j][k][c] = wa * va.s[k + 1][c] + wb * vb.s[k + 1][c];
                    piece.stokes_se[side][j][k][c] =
                        std::hypot(wa * va.se[k + 1][c], wb * vb.se[k + 1][c]);
                }
        }
    }
    const EnergyBudget& ba = a.incidences[0].budget;
    const EnergyBudget& bb = b.incidences[0].budget;
    for (int t = 0; t < kBudgetTerms; ++t)
        piece.budget.term[t] = ba.term[t] * wa + bb.term[t] * wb;
    for (int c = 0; c < 3; ++c) {
        piece.budget.reflected_se[c] = std::hypot(wa * ba.reflected_se[c], wb * bb.reflected_se[c]);
        piece.budget.transmitted_se[c] =
            std::hypot(wa * ba.transmitted_se[c], wb * bb.transmitted_se[c]);
    }
    return serialize(key, piece);
}

ReferencePiece store_reference_piece(const std::filesystem::path& cache_dir,
                                     const ReferenceKey& key, const std::string& bytes) {
    // Return exactly what a later run will read back (float32 tables), so that a resumed study
    // computes the same metrics as an uninterrupted one.
    ReferencePiece stored;
    if (!deserialize(bytes, key, stored))
        throw InputError(key.config_id, key.file_name(),
                         "the computed reference piece does not match its key (a process of a "
                         "different lamina version?)");
    const std::filesystem::path dir = cache_dir / key.config_id;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    write_file_atomic(dir / key.file_name(), bytes);
    return stored;
}

ReferencePiece reference_piece(const std::filesystem::path& cache_dir, const ReferenceKey& key,
                               int threads, const std::function<void(std::uint64_t)>& on_progress,
                               bool* computed) {
    if (std::optional<ReferencePiece> cached = load_reference_piece(cache_dir, key)) {
        if (computed) *computed = false;
        return *cached;
    }
    ReferencePiece stored =
        store_reference_piece(cache_dir, key, compute_reference_piece(key, threads, on_progress));
    if (computed) *computed = true;
    return stored;
}

}  // namespace lamina
