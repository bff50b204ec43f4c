#include "study/study.h"

#include "model_source_digest.h"

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/packed_array.h"
#include "core/progress.h"
#include "core/table.h"
#include "lamina/version.h"
#include "models/lamina1/lamina1.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/spectral_projection.h"
#include "study/reference.h"
#include "study/report_values.h"
#include "study/summary.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>

namespace lamina {

namespace {

constexpr const char* kStateFormat = "lamina-study-state v1";

nlohmann::json rgb(const Rgbd& v) {
    return nlohmann::json::array({v[0], v[1], v[2]});
}

std::string csv_number(double v) {
    return std::isfinite(v) ? fmt::format("{}", v) : "";
}

struct ConfigResult {
    std::vector<MetricRow> rows;
    std::vector<Rgbd> lost_microsurface;  ///< the reference's, per incidence
    double reference_seconds = 0;         ///< the simulation time stored in its pieces
};

// ---- The digests of a configuration's inputs ---------------------------------------------------

// Everything a model's binned table depends on: the model (name, options, lamina's version and
// the digest of the models' code, so that an edited model is binned again), the stack, the
// incidences, the grid and the binning rule.
std::string model_key(const std::string& name, const StudyConfiguration& config,
                      const StudySettings& s, const std::vector<StudyIncidence>& incidences,
                      const HemisphereGrid& grid) {
    // A model from elsewhere (a table file, a Python plugin) may change without its name
    // changing: it is evaluated again on every run (a key no earlier run had).
    for (const ExternalModel& e : s.external_models)
        if (e.name == name)
            return fmt::format("external {} | {} | run {}", name, e.source,
                               std::chrono::system_clock::now().time_since_epoch().count());
    const ModelSpec spec = parse_model_spec(name, "--models");
    const BinnedOptions b;
    // A folded configuration's key is the one it always had; an unfolded one's names its grid
    // and its incidences' azimuths.
    std::string unfolded;
    if (grid.is_unfolded()) {
        std::vector<double> theta, phi;
        for (const StudyIncidence& inc : incidences) {
            theta.push_back(inc.theta_i);
            phi.push_back(inc.phi_i);
        }
        unfolded = fmt::format(" | incidences {} phi_i {} | grid {}", fmt::join(theta, ","),
                               fmt::join(phi, ","), grid.to_string());
    }
    // A spectral configuration's models are projected over the reference's range; a key without
    // it is the one an RGB configuration always had.
    if (is_spectral_run(config.stack, s.reference))
        unfolded += fmt::format(" | spectral {}-{} nm", s.reference.spectral_min_nm,
                                s.reference.spectral_max_nm);
    return fmt::format(
        "lamina {} code {} | model {} | options {} | stack {} | theta_i {} | grid {} | binned {} "
        "{} "
        "{} {} {}{}",
        kVersion, kModelSourceDigest, name,
        nlohmann::json(resolve_options(*spec.entry, spec.assignments, "--models")).dump(),
        stack_to_json(config.stack).dump(), fmt::join(s.reference.theta_i_deg, ","),
        s.reference.grid.to_string(), b.rel_tol, b.abs_tol, b.max_depth, b.peak_depth,
        b.eval_budget, unfolded);
}

std::filesystem::path state_path(const std::filesystem::path& out_dir, const std::string& id) {
    return out_dir / "cache" / "study" / (id + ".json");
}

nlohmann::json read_state(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return nullptr;
    try {
        // Bounded: a state is tens of kB, and a device or a pipe in its place is not read.
        const std::optional<std::string> text = read_cache_file(path, std::size_t(256) << 20);
        if (!text) return nullptr;
        nlohmann::json j = nlohmann::json::parse(*text);
        // Another format's state (a newer or an edited one) is not read.
        return j.is_object() && j.value("format", "") == kStateFormat ? j : nlohmann::json();
    } catch (const std::exception&) {
        return nullptr;  // a damaged state is recomputed, never trusted
    }
}

double num_of(const nlohmann::json& v) {
    return v.is_number() ? v.get<double>() : NAN;
}

// A metric row as the state keeps it (every double exactly: JSON numbers round-trip).
nlohmann::json row_json(const MetricRow& r) {
    const LobeMetrics &m = r.metrics, &f = r.floor;
    nlohmann::json j = {r.theta_i,
                        std::string(1, r.side),
                        r.channel,
                        r.supported,
                        json_number(m.misplaced_energy),
                        json_number(m.misplaced_floor),
                        json_number(m.albedo_ref),
                        json_number(m.albedo_model),
                        json_number(m.albedo_error),
                        json_number(m.rmse),
                        json_number(m.log_rmse),
                        json_number(f.misplaced_energy),
                        json_number(f.misplaced_floor)};
    if (r.phi_i != 0) j.push_back(r.phi_i);  // a 14th field only where the light is off φ = 0
    return j;
}

MetricRow row_from_json(const nlohmann::json& j, const StudyConfiguration& c,
                        const std::string& model) {
    MetricRow r;
    r.config = c.id;
    r.category = c.category;
    r.model = model;
    r.theta_i = j.at(0).get<double>();
    r.side = j.at(1).get<std::string>().at(0);
    r.channel = j.at(2).get<int>();
    r.supported = j.at(3).get<bool>();
    r.metrics.misplaced_energy = num_of(j.at(4));
    r.metrics.misplaced_floor = num_of(j.at(5));
    r.metrics.albedo_ref = num_of(j.at(6));
    r.metrics.albedo_model = num_of(j.at(7));
    r.metrics.albedo_error = num_of(j.at(8));
    r.metrics.rmse = num_of(j.at(9));
    r.metrics.log_rmse = num_of(j.at(10));
    r.floor.misplaced_energy = num_of(j.at(11));
    r.floor.misplaced_floor = num_of(j.at(12));
    if (j.size() > 13) r.phi_i = j.at(13).get<double>();
    // A state is the study's own file, but read back it is input: a row out of range (an edited
    // or damaged file) is not trusted, and the caller recomputes the configuration's rows.
    bool sane = r.theta_i >= 0 && r.theta_i < 90 && (r.side == 'R' || r.side == 'T') &&
                r.channel >= 0 && r.channel < 3 && r.phi_i >= 0 && r.phi_i <= 360;
    for (const double v :
         {r.metrics.misplaced_energy, r.metrics.misplaced_floor, r.metrics.albedo_ref,
          r.metrics.albedo_model, r.metrics.albedo_error, r.metrics.rmse, r.metrics.log_rmse,
          r.floor.misplaced_energy, r.floor.misplaced_floor})
        sane = sane && (std::isnan(v) || std::abs(v) <= kMaxBinValue);  // NaN: null, not computed
    // Misplaced energies, their floors and the errors' norms are never negative.
    for (const double v : {r.metrics.misplaced_energy, r.metrics.misplaced_floor, r.metrics.rmse,
                           r.metrics.log_rmse, r.floor.misplaced_energy, r.floor.misplaced_floor})
        sane = sane && !(v < 0);
    if (!sane) throw std::runtime_error("a state row out of range");
    return r;
}

// A state's rows of one model, from `first` on, checked to be those a run writes, in its order:
// per incidence, per side (R, then T where the stack transmits), per channel. Rows at other
// incidences or sides, or fewer (an edited or damaged file), are not trusted: the caller
// recomputes the configuration.
void check_row_sequence(const std::vector<MetricRow>& rows, std::size_t first,
                        const std::vector<StudyIncidence>& incidences, int sides) {
    if (rows.size() - first != incidences.size() * std::size_t(sides) * 3)
        throw std::runtime_error("a state with missing rows");
    for (std::size_t i = 0; i < incidences.size(); ++i)
        for (int side = 0; side < sides; ++side)
            for (int c = 0; c < 3; ++c) {
                const MetricRow& r =
                    rows[first + (i * std::size_t(sides) + std::size_t(side)) * 3 + std::size_t(c)];
                if (r.theta_i != incidences[i].theta_i || r.phi_i != incidences[i].phi_i ||
                    r.side != (side == 0 ? 'R' : 'T') || r.channel != c)
                    throw std::runtime_error("a state's rows are not this run's");
            }
}

// A packed array (core/packed_array.h) of float16 or float32 values.
std::string tables_bytes(TablesFormat format, const std::vector<float>& data,
                         const std::vector<std::size_t>& shape,
                         const std::vector<std::string>& axes) {
    return packed_array_file(data, shape, format == TablesFormat::Half, axes);
}

// ---- One configuration
// ---------------------------------------------------------------------------

struct ModelOutcome {
    std::string name, key;
    Support support;
    std::vector<MetricRow> rows;
    nlohmann::json albedo;     ///< {"R": [rgb or null per incidence], "T": …}
    std::vector<float> table;  ///< [incidence][side][bin][channel]; NaN where not supported
    bool reused = false;
};

// One configuration of a run: reference pieces, models, metrics; writes configs/<id>/ — or, when
// its inputs are those of the last run, reads back what that run found. Each step is a method,
// in the order run() calls them.
class ConfigurationRun {
  public:
    ConfigurationRun(const StudyConfiguration& config, const StudySettings& s,
                     const std::vector<std::string>& model_names,
                     const std::filesystem::path& out_dir, Progress& progress, StudyWork& work,
                     StudyTimes& times)
        : config_(config),
          s_(s),
          model_names_(model_names),
          out_dir_(out_dir),
          progress_(progress),
          work_(work),
          times_(times),
          incidences_(study_incidences(config.stack, s.reference)),
          n_inc_(incidences_.size()),
          grid_(study_grid(config.stack, s.reference)),
          bins_(grid_.size()),
          config_dir_(out_dir / "configs" / config.id) {
        for (std::size_t j = 0; j < bins_; ++j)
            omega_.push_back(grid_.projected_solid_angle(j));
    }

    ConfigResult run() {
        digest_inputs();
        if (read_back()) return result_;
        PhaseTimer reference;
        simulate_reference();
        reference.add_to(times_.reference);
        // The tables one model after the other (each binned on every thread), then the
        // comparisons, independent of each other, over the threads.
        std::vector<ModelOutcome> models;
        std::vector<BinnedTable> tables(model_names_.size());
        if (times_.per_model.size() < model_names_.size())
            for (std::size_t k = times_.per_model.size(); k < model_names_.size(); ++k)
                times_.per_model.push_back({model_names_[k], {}});
        for (std::size_t k = 0; k < model_names_.size(); ++k) {
            PhaseTimer model;
            models.push_back(model_outcome(k, tables[k]));
            model.add_to(times_.per_model[k].second);
            model.add_to(times_.models);
        }
        PhaseTimer comparisons;
        compare_models(models, tables);
        comparisons.add_to(times_.comparisons);
        for (const ModelOutcome& m : models)
            result_.rows.insert(result_.rows.end(), m.rows.begin(), m.rows.end());
        PhaseTimer outputs;
        write_outputs(models);
        write_state(models);
        outputs.add_to(times_.outputs);
        return result_;
    }

  private:
    // 0. The digests of the inputs, and what the last run left.
    void digest_inputs() {
        ref_digest_ = fnv1a("reference");
        for (const StudyIncidence& inc : incidences_) {
            keys_.push_back(study_reference_key(config_, inc, s_));
            ref_digest_ = fnv1a(keys_.back().canonical(), ref_digest_);
        }
        stokes_ = keys_.front().settings.stokes_tallies && s_.tables != TablesFormat::None;
        outputs_digest_ = fnv1a(fmt::format("{} | reference {} | tables {}{}", kStateFormat,
                                            digest_hex(ref_digest_), enum_text(s_.tables),
                                            stokes_ ? " | stokes" : ""));
        for (const std::string& name : model_names_) {
            model_keys_.push_back(
                digest_hex(fnv1a(model_key(name, config_, s_, incidences_, grid_))));
            outputs_digest_ = fnv1a(" | " + name + " " + model_keys_.back(), outputs_digest_);
        }
        state_ = s_.recompute ? nlohmann::json() : read_state(state_path(out_dir_, config_.id));
    }

    // The last run's results when every input is unchanged and its outputs are there.
    bool read_back() {
        const bool outputs_there =
            std::filesystem::exists(config_dir_ / "config.json") &&
            (s_.tables == TablesFormat::None ||
             (std::filesystem::exists(config_dir_ / "tables.lza") &&
              std::filesystem::exists(config_dir_ / "reference_se.lza") &&
              (!stokes_ || std::filesystem::exists(config_dir_ / "reference_stokes.lza"))));
        if (!state_.is_object() || state_.value("outputs", "") != digest_hex(outputs_digest_) ||
            !outputs_there)
            return false;
        try {
            const int sides = config_.stack.transmits() ? 2 : 1;
            for (const std::string& name : model_names_) {
                const std::size_t first = result_.rows.size();
                for (const nlohmann::json& r : state_.at("models").at(name).at("rows"))
                    result_.rows.push_back(row_from_json(r, config_, name));
                check_row_sequence(result_.rows, first, incidences_, sides);
            }
            // The fractions of the incident energy lost on the microsurfaces, per incidence:
            // finite and of the order of 1 (a spectral run's sRGB may leave [0, 1]).
            for (const nlohmann::json& v : state_.at("lost_microsurface")) {
                const Rgbd lost(v.at(0).get<double>(), v.at(1).get<double>(),
                                v.at(2).get<double>());
                for (int c = 0; c < 3; ++c)
                    if (!(std::abs(lost[c]) <= 10))
                        throw std::runtime_error("a state's loss out of range");
                result_.lost_microsurface.push_back(lost);
            }
            if (result_.lost_microsurface.size() != incidences_.size())
                throw std::runtime_error("a state with missing losses");
            result_.reference_seconds = state_.value("reference_seconds", 0.0);
            work_.model_tables_reused += model_names_.size();
            ++work_.configurations_unchanged;
            return true;
        } catch (const std::exception&) {
            result_ = {};  // a damaged state: recompute
            return false;
        }
    }

    // 1. The reference, one resumable piece per incidence.
    void simulate_reference() {
        for (const ReferenceKey& key : keys_) {
            bool computed = false;
            pieces_.push_back(reference_piece(
                reference_cache_dir(out_dir_), key, s_.reference.threads,
                [&](std::uint64_t n) { progress_.advance(n); }, &computed));
            work_.reference_pieces_computed += computed;
            result_.reference_seconds += pieces_.back().seconds;
        }
        transmits_ = pieces_.front().has_transmission;
        n_sides_ = transmits_ ? 2 : 1;
        block_ = std::size_t(n_sides_) * bins_ * 3;
        same_reference_ =
            state_.is_object() && state_.value("reference", "") == digest_hex(ref_digest_);
    }

    // What the last run's tables hold for `name`, for a model whose inputs did not change (read
    // once, when a model needs them; exact in the same format: a float16 or float32 is written
    // back as read); null when there is none.
    const float* old_table_of(const std::string& name) {
        if (s_.tables == TablesFormat::None) return nullptr;
        if (!old_loaded_) {
            old_loaded_ = true;
            try {
                if (state_.value("tables", "") == enum_text(s_.tables)) {
                    const nlohmann::json cj = nlohmann::json::parse(read_regular_file_bounded(
                        config_dir_ / "config.json", kMaxTableFileBytes, "the configuration"));
                    old_sources_ = cj.at("sources").get<std::vector<std::string>>();
                    NpyFloat32 t = read_study_array(config_dir_, "tables");
                    if (t.shape == std::vector<std::size_t>{
                                       old_sources_.size(), n_inc_, std::size_t(n_sides_),
                                       std::size_t(grid_.n_theta()), std::size_t(grid_.n_phi()), 3})
                        old_tables_ = std::move(t);
                }
            } catch (const std::exception&) {
                old_tables_.reset();
            }
        }
        if (!old_tables_) return nullptr;
        const auto it = std::find(old_sources_.begin(), old_sources_.end(), name);
        if (it == old_sources_.end()) return nullptr;
        return old_tables_->data.data() + std::size_t(it - old_sources_.begin()) * n_inc_ * block_;
    }

    // 2. Model k on the same bins (its table in `table`, compared by compare_models), unless its
    //    inputs and the reference are unchanged.
    ModelOutcome model_outcome(std::size_t k, BinnedTable& table) {
        const std::string& name = model_names_[k];
        ModelOutcome m{name, model_keys_[k], {}, {}, {}, {}, false};
        if (same_reference_ && state_.contains("models") && state_["models"].contains(name) &&
            state_["models"][name].value("key", "") == m.key) {
            try {
                const nlohmann::json& ms = state_["models"][name];
                const float* old = old_table_of(name);
                if (s_.tables == TablesFormat::None || old) {
                    for (const nlohmann::json& r : ms.at("rows"))
                        m.rows.push_back(row_from_json(r, config_, name));
                    check_row_sequence(m.rows, 0, incidences_, n_sides_);
                    m.support.brdf = ms.at("support").at("R").get<bool>();
                    m.support.btdf = ms.at("support").at("T").get<bool>();
                    m.support.reason = ms.at("support").at("reason").get<std::string>();
                    m.albedo = ms.at("albedo");
                    if (old) m.table.assign(old, old + n_inc_ * block_);
                    m.reused = true;
                }
            } catch (const std::exception&) {
                m = ModelOutcome{name, model_keys_[k], {}, {}, {}, {}, false};
            }
        }
        if (m.reused) {
            ++work_.model_tables_reused;
            return m;
        }
        ++work_.model_tables_computed;
        table = model_table(m);
        return m;
    }

    // The computed models' comparisons, in parallel: each reads the reference and its own table
    // and writes its own outcome only.
    void compare_models(std::vector<ModelOutcome>& models, const std::vector<BinnedTable>& tables) {
        const long n = long(models.size());
#pragma omp parallel for schedule(dynamic, 1)
        for (long k = 0; k < n; ++k)
            if (!models[std::size_t(k)].reused)
                compare_model(models[std::size_t(k)], tables[std::size_t(k)]);
    }

    // A model's binned table: from elsewhere (a model table, a Python plugin; checked against the
    // study) or the registry's model on the bins; its support in m.
    BinnedTable model_table(ModelOutcome& m) {
        BinnedTable table;
        const auto external =
            std::find_if(s_.external_models.begin(), s_.external_models.end(),
                         [&](const ExternalModel& e) { return e.name == m.name; });
        if (external != s_.external_models.end() && grid_.is_unfolded() && !external->unfolded) {
            // A model table's rows carry θi only (brdf.csv): no table of an unfolded
            // configuration, whose incidences differ in φi too.
            m.support.reason = fmt::format(
                "{}: a model table covers folded configurations only (this one is compared on "
                "the unfolded grid, lit from several azimuths)",
                external->source);
        } else if (external != s_.external_models.end()) {
            table = external->table(config_, incidences_, grid_);
            if (table.has_reflection || table.has_transmission) {
                std::vector<double> theta_i;
                for (const StudyIncidence& inc : incidences_)
                    theta_i.push_back(inc.theta_i);
                check_external_table(table, grid_, theta_i, transmits_, external->source);
            }
            m.support.brdf = table.has_reflection;
            m.support.btdf = transmits_ && table.has_transmission;
            if (!m.support.brdf || (transmits_ && !m.support.btdf))
                m.support.reason =
                    table.has_reflection || table.has_transmission
                        ? fmt::format("{} has no {} rows", external->source,
                                      m.support.brdf ? "T" : "R")
                        : fmt::format("{} has no table for {}", external->source, config_.id);
        } else {
            // On a spectral reference (a stack with a spectral value) the model's colour, as
            // the reference's tables are (models/spectral_projection.h).
            const std::unique_ptr<Model> model =
                is_spectral_run(config_.stack, s_.reference)
                    ? make_spectral_projection(
                          [&](const Stack& at) { return make_model(m.name, at); }, config_.stack,
                          SpectralQuadrature{.min_nm = s_.reference.spectral_min_nm,
                                             .max_nm = s_.reference.spectral_max_nm})
                    : make_model(m.name, config_.stack);
            m.support = model->support();
            if (m.support.brdf || m.support.btdf) table = bin_registry_model(*model);
        }
        return table;
    }

    // The registry's model on the bins of every incidence: as it always was on a folded grid;
    // on an unfolded one, each azimuth's incidences at once, gathered in the incidences' order.
    BinnedTable bin_registry_model(const Model& model) const {
        if (!grid_.is_unfolded()) return bin_model(model, grid_, s_.reference.theta_i_deg);
        return gather_azimuths(incidences_, model.name(),
                               [&](const std::vector<double>& theta_i, double phi_i) {
                                   return bin_model(model, grid_, theta_i, phi_i);
                               });
    }

    // The model's table, albedos and metric rows against the reference.
    void compare_model(ModelOutcome& m, const BinnedTable& table) {
        m.table.assign(n_inc_ * block_, NAN);
        m.albedo = nlohmann::json::object();
        for (std::size_t i = 0; i < n_inc_; ++i)
            for (int side = 0; side < n_sides_; ++side) {
                const bool supported = side == 0 ? m.support.brdf : m.support.btdf;
                const char* side_name = side == 0 ? "R" : "T";
                const double theta_i = incidences_[i].theta_i, phi_i = incidences_[i].phi_i;
                if (!supported) {
                    m.albedo[side_name].push_back(nullptr);
                    for (int c = 0; c < 3; ++c)
                        m.rows.push_back({config_.id,
                                          config_.category,
                                          m.name,
                                          theta_i,
                                          phi_i,
                                          side_name[0],
                                          c,
                                          false,
                                          {},
                                          pieces_[i].floor[side][c]});
                    continue;
                }
                const BinnedLobe& lobe =
                    table.lobe(i, side == 0 ? Side::Reflection : Side::Transmission);
                Rgbd a(0.0);
                for (std::size_t j = 0; j < bins_; ++j)
                    for (int c = 0; c < 3; ++c) {
                        m.table[(i * n_sides_ + side) * bins_ * 3 + j * 3 + c] =
                            float(lobe.f[j][c]);
                        a[c] += lobe.f[j][c] * omega_[j];
                    }
                m.albedo[side_name].push_back(rgb(a));
                for (int c = 0; c < 3; ++c)
                    m.rows.push_back({config_.id, config_.category, m.name, theta_i, phi_i,
                                      side_name[0], c, true,
                                      lobe_metrics(grid_, pieces_[i].f[side], lobe.f, c),
                                      pieces_[i].floor[side][c]});
            }
    }

    // 3. configs/<id>/: config.json, tables.lza, reference_se.lza (each rewritten only if changed;
    //    the .npy tables of a study written before packed arrays are removed).
    void write_outputs(const std::vector<ModelOutcome>& models) {
        const std::size_t n_sources = 1 + models.size();
        nlohmann::json albedo;
        nlohmann::json supported = nlohmann::json::object();
        nlohmann::json sources = {"reference"};
        std::vector<float> tables, ses;
        if (s_.tables != TablesFormat::None) {
            tables.assign(n_sources * n_inc_ * block_, NAN);
            ses.assign(n_inc_ * block_, 0.0f);
        }
        for (std::size_t i = 0; i < n_inc_; ++i)
            for (int side = 0; side < n_sides_; ++side) {
                Rgbd a(0.0);
                for (std::size_t j = 0; j < bins_; ++j)
                    for (int c = 0; c < 3; ++c) {
                        const std::size_t at = (i * n_sides_ + side) * bins_ * 3 + j * 3 + c;
                        if (!tables.empty()) {
                            tables[at] = float(pieces_[i].f[side][j][c]);
                            ses[at] = float(pieces_[i].se[side][j][c]);
                        }
                        a[c] += pieces_[i].f[side][j][c] * omega_[j];
                    }
                albedo["reference"][side == 0 ? "R" : "T"].push_back(rgb(a));
            }
        for (std::size_t k = 0; k < models.size(); ++k) {
            const ModelOutcome& m = models[k];
            sources.push_back(m.name);
            supported[m.name] = {
                {"R", m.support.brdf}, {"T", m.support.btdf}, {"reason", m.support.reason}};
            albedo[m.name] = m.albedo;
            if (!tables.empty())
                std::copy(m.table.begin(), m.table.end(),
                          tables.begin() + (1 + k) * n_inc_ * block_);
        }
        const std::vector<std::size_t> shape = {n_sources,
                                                n_inc_,
                                                std::size_t(n_sides_),
                                                std::size_t(grid_.n_theta()),
                                                std::size_t(grid_.n_phi()),
                                                3};
        nlohmann::json cj = config_json(sources, supported, albedo, shape);
        // lamina-1's GLSL states for the explorer's live spheres (docs/formats.md): the
        // stack's own, then the per-material part of each variant config.json lists.
        std::string why;
        const Lamina1GpuStates gpu = lamina1_gpu_states(config_.stack, {}, why);
        std::string gpu_bytes;
        if (!gpu.state.empty()) {
            nlohmann::json variants = nlohmann::json::array();
            for (const Lamina1GpuVariant& v : gpu.variants)
                variants.push_back({v.parameter, v.value});
            cj["lamina1_gpu"] = {{"file", "lamina1_gpu.f32"},
                                 {"state", gpu.state.size()},
                                 {"head", gpu.head},
                                 {"tail", gpu.tail},
                                 {"variants", variants}};
            gpu_bytes.append(reinterpret_cast<const char*>(gpu.state.data()),
                             gpu.state.size() * sizeof(float));
            gpu_bytes.append(reinterpret_cast<const char*>(gpu.heads.data()),
                             gpu.heads.size() * sizeof(float));
        }
        bool wrote = false;
        {
            StagedOutput out(config_dir_);
            if (s_.tables != TablesFormat::None) {
                const std::vector<std::string> axes = {"source",    "incidence", "side",
                                                       "theta_bin", "phi_bin",   "channel"};
                wrote |=
                    out.add_if_changed("tables.lza", tables_bytes(s_.tables, tables, shape, axes));
                wrote |= out.add_if_changed(
                    "reference_se.lza",
                    tables_bytes(s_.tables, ses,
                                 std::vector<std::size_t>(shape.begin() + 1, shape.end()),
                                 std::vector<std::string>(axes.begin() + 1, axes.end())));
            }
            if (stokes_)
                wrote |= out.add_if_changed(
                    "reference_stokes.lza",
                    tables_bytes(s_.tables, stokes_table(), stokes_shape(), kStokesAxes));
            if (!gpu_bytes.empty()) wrote |= out.add_if_changed("lamina1_gpu.f32", gpu_bytes);
            wrote |= out.add_if_changed("config.json", cj.dump(1) + "\n");
            out.commit();
        }
        if (gpu_bytes.empty()) {
            std::error_code ec;
            wrote |= std::filesystem::remove(config_dir_ / "lamina1_gpu.f32", ec);
        }
        for (const char* name : {"tables.npy", "reference_se.npy", "tables.lza", "reference_se.lza",
                                 "reference_stokes.lza"})
            if (s_.tables == TablesFormat::None || std::string_view(name).ends_with(".npy") ||
                (!stokes_ && std::string_view(name) == "reference_stokes.lza")) {
                std::error_code ec;
                wrote |= std::filesystem::remove(config_dir_ / name, ec);
            }
        work_.configurations_written += wrote;
        work_.configurations_unchanged += !wrote;
    }

    // reference_stokes.lza: [quantity (S, se), incidence, side, component (S1, S2, S3), θ bin,
    // φ bin, channel], the reference's Stokes components for unpolarized incident light and their
    // standard errors (1/sr).
    static inline const std::vector<std::string> kStokesAxes = {
        "quantity", "incidence", "side", "component", "theta_bin", "phi_bin", "channel"};
    std::vector<std::size_t> stokes_shape() const {
        return {2,
                n_inc_,
                std::size_t(n_sides_),
                3,
                std::size_t(grid_.n_theta()),
                std::size_t(grid_.n_phi()),
                3};
    }
    std::vector<float> stokes_table() const {
        std::vector<float> out;
        out.reserve(2 * n_inc_ * std::size_t(n_sides_) * 3 * bins_ * 3);
        for (int q = 0; q < 2; ++q)
            for (std::size_t i = 0; i < n_inc_; ++i)
                for (int side = 0; side < n_sides_; ++side) {
                    const auto& v = q == 0 ? pieces_[i].stokes[side] : pieces_[i].stokes_se[side];
                    LAMINA_CHECK(v.size() == bins_);
                    for (std::size_t k = 0; k < 3; ++k)
                        for (std::size_t j = 0; j < bins_; ++j)
                            for (int c = 0; c < 3; ++c)
                                out.push_back(float(v[j][k][c]));
                }
        return out;
    }

    // config.json: the configuration, its sources, what each supports, the albedos, the
    // reference's energy budget per incidence and the tables' layout.
    nlohmann::json config_json(const nlohmann::json& sources, const nlohmann::json& supported,
                               const nlohmann::json& albedo,
                               const std::vector<std::size_t>& shape) {
        nlohmann::json energy = nlohmann::json::array();
        for (std::size_t i = 0; i < n_inc_; ++i) {
            result_.lost_microsurface.push_back(pieces_[i].budget[BudgetTerm::LostMicrosurface]);
            nlohmann::json e;
            e["theta_i"] = incidences_[i].theta_i;
            if (grid_.is_unfolded()) e["phi_i"] = incidences_[i].phi_i;
            for (int t = 0; t < kBudgetTerms; ++t)
                e[kBudgetTermNames[t]] = rgb(pieces_[i].budget.term[t]);
            e["reflected_se"] = rgb(pieces_[i].budget.reflected_se);
            e["transmitted_se"] = rgb(pieces_[i].budget.transmitted_se);
            energy.push_back(e);
        }
        nlohmann::json cj;
        cj["id"] = config_.id;
        cj["category"] = config_.category;
        cj["parameters"] = config_.parameters;
        cj["stack"] = stack_to_json(config_.stack);
        cj["sides"] = transmits_ ? nlohmann::json{"R", "T"} : nlohmann::json{"R"};
        // A spectral reference's channels are linear sRGB under D65 over its range (tables.lza).
        if (is_spectral_run(config_.stack, s_.reference))
            cj["spectral"] = {{"min_nm", s_.reference.spectral_min_nm},
                              {"max_nm", s_.reference.spectral_max_nm},
                              {"channels", "linear sRGB (D65)"}};
        if (grid_.is_unfolded()) {
            // An unfolded configuration's incidences are its own (θi, φi) pairs, on its grid.
            nlohmann::json theta = nlohmann::json::array(), phi = nlohmann::json::array();
            for (const StudyIncidence& inc : incidences_) {
                theta.push_back(inc.theta_i);
                phi.push_back(inc.phi_i);
            }
            cj["theta_i"] = theta;
            cj["phi_i"] = phi;
            cj["grid"] = grid_.to_string();
        } else {
            cj["theta_i"] = s_.reference.theta_i_deg;
        }
        cj["sources"] = sources;
        cj["supported"] = supported;
        cj["albedo"] = albedo;
        cj["energy"] = energy;
        if (s_.tables == TablesFormat::None)
            cj["tables"] = nullptr;
        else
            cj["tables"] = {
                {"file", "tables.lza"},
                {"dtype", s_.tables == TablesFormat::Half ? "float16" : "float32"},
                {"shape", shape},
                {"axes", {"source", "incidence", "side", "theta_bin", "phi_bin", "channel"}}};
        if (stokes_)
            cj["stokes"] = {{"file", "reference_stokes.lza"},
                            {"dtype", s_.tables == TablesFormat::Half ? "float16" : "float32"},
                            {"shape", stokes_shape()},
                            {"axes", kStokesAxes}};
        return cj;
    }

    // 4. What a later run with the same inputs reads back instead of all of the above.
    void write_state(const std::vector<ModelOutcome>& models) {
        nlohmann::json st;
        st["format"] = kStateFormat;
        st["outputs"] = digest_hex(outputs_digest_);
        st["reference"] = digest_hex(ref_digest_);
        st["tables"] = enum_text(s_.tables);
        st["reference_seconds"] = result_.reference_seconds;
        st["lost_microsurface"] = nlohmann::json::array();
        for (const Rgbd& v : result_.lost_microsurface)
            st["lost_microsurface"].push_back(rgb(v));
        for (const ModelOutcome& m : models) {
            nlohmann::json rows = nlohmann::json::array();
            for (const MetricRow& r : m.rows)
                rows.push_back(row_json(r));
            st["models"][m.name] = {
                {"key", m.key},
                {"support",
                 {{"R", m.support.brdf}, {"T", m.support.btdf}, {"reason", m.support.reason}}},
                {"albedo", m.albedo},
                {"rows", rows}};
        }
        std::error_code ec;
        std::filesystem::create_directories(state_path(out_dir_, config_.id).parent_path(), ec);
        write_file_if_changed(state_path(out_dir_, config_.id), st.dump() + "\n");
    }

    const StudyConfiguration& config_;
    const StudySettings& s_;
    const std::vector<std::string>& model_names_;
    const std::filesystem::path& out_dir_;
    Progress& progress_;
    StudyWork& work_;
    StudyTimes& times_;
    const std::vector<StudyIncidence> incidences_;
    const std::size_t n_inc_;
    const HemisphereGrid grid_;  ///< folded, or unfolded (an anisotropic stack, φi ≠ 0)
    const std::size_t bins_;
    const std::filesystem::path config_dir_;
    std::vector<double> omega_;  ///< each bin's projected solid angle Ω⊥ (sr)

    std::vector<ReferenceKey> keys_;
    std::uint64_t ref_digest_ = 0, outputs_digest_ = 0;
    std::vector<std::string> model_keys_;
    nlohmann::json state_;
    std::vector<ReferencePiece> pieces_;
    bool transmits_ = false, same_reference_ = false;
    bool stokes_ = false;  ///< reference_stokes.lza is written (study_reference_key)
    int n_sides_ = 1;
    std::size_t block_ = 0;  ///< one incidence of one source: sides × bins × channels
    bool old_loaded_ = false;
    std::optional<NpyFloat32> old_tables_;
    std::vector<std::string> old_sources_;
    ConfigResult result_;
};

}  // namespace

std::uint64_t preset_particles(const std::string& preset) {
    if (preset == "quick") return 1'000'000;
    if (preset == "standard") return 10'000'000;
    if (preset == "paper") return 160'000'000;
    throw InputError("command line", "--preset",
                     fmt::format("'{}' is not a preset: use quick (10^6 particles per incidence), "
                                 "standard (10^7) or paper (1.6·10^8)",
                                 preset));
}

std::vector<StudyIncidence> study_incidences(const Stack& stack,
                                             const SimulationSettings& reference) {
    std::vector<StudyIncidence> out;
    for (double theta_i : reference.theta_i_deg) {
        if (!stack.is_anisotropic()) {
            out.push_back({theta_i, reference.phi_i_deg});
            continue;
        }
        for (double phi_i : kAnisotropicPhiIDeg) {
            out.push_back({theta_i, phi_i});
            if (theta_i == 0) break;  // the normal: one light whatever its azimuth
        }
    }
    return out;
}

HemisphereGrid study_grid(const Stack& stack, const SimulationSettings& reference) {
    return simulation_grid(stack, reference);
}

BinnedTable gather_azimuths(const std::vector<StudyIncidence>& incidences, const std::string& where,
                            const std::function<BinnedTable(const std::vector<double>& theta_i_deg,
                                                            double phi_i_deg)>& at_azimuth) {
    std::vector<double> azimuths, thetas;
    for (const StudyIncidence& inc : incidences) {
        if (std::find(azimuths.begin(), azimuths.end(), inc.phi_i) == azimuths.end())
            azimuths.push_back(inc.phi_i);
        thetas.push_back(inc.theta_i);
    }
    BinnedTable out;
    for (double phi : azimuths) {
        std::vector<double> at_phi;
        for (const StudyIncidence& inc : incidences)
            if (inc.phi_i == phi) at_phi.push_back(inc.theta_i);
        BinnedTable t = at_azimuth(at_phi, phi);
        if (!t.has_reflection && !t.has_transmission) return t;  // no side: not supported
        if (t.lobes.size() != at_phi.size())
            throw InputError(where, "theta_i",
                             fmt::format("{} incidences for the {} at φi = {}°", t.lobes.size(),
                                         at_phi.size(), phi));
        if (out.lobes.empty()) {
            out = t;
            out.theta_i_deg = thetas;
            out.lobes.assign(incidences.size(), t.lobes.front());
        } else if (!(t.grid == out.grid) || t.has_reflection != out.has_reflection ||
                   t.has_transmission != out.has_transmission) {
            throw InputError(where, "grid",
                             fmt::format("the table at φi = {}° has another grid or other sides "
                                         "than at φi = {}°",
                                         phi, azimuths.front()));
        }
        std::size_t k = 0;
        for (std::size_t i = 0; i < incidences.size(); ++i)
            if (incidences[i].phi_i == phi) out.lobes[i] = std::move(t.lobes[k++]);
    }
    return out;
}

std::string metrics_csv(const std::vector<MetricRow>& rows) {
    // The phi_i column only where some light is off φ = 0: a study of folded configurations has
    // the columns it always had.
    const bool with_phi =
        std::any_of(rows.begin(), rows.end(), [](const MetricRow& r) { return r.phi_i != 0; });
    std::string header = kMetricsCsvHeader;
    if (with_phi) header.replace(header.find(",side,"), 6, ",phi_i,side,");
    std::string out = header + "\n";
    for (const MetricRow& r : rows) {
        fmt::format_to(std::back_inserter(out), "{},{},{},{},", r.config, r.category, r.model,
                       r.theta_i);
        if (with_phi) fmt::format_to(std::back_inserter(out), "{},", r.phi_i);
        fmt::format_to(std::back_inserter(out), "{},{},", r.side, kChannelNames[r.channel]);
        if (r.supported)
            fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{},{},{},true\n",
                           csv_number(r.metrics.misplaced_energy),
                           csv_number(r.metrics.misplaced_floor), csv_number(r.metrics.albedo_ref),
                           csv_number(r.metrics.albedo_model), csv_number(r.metrics.albedo_error),
                           csv_number(r.metrics.rmse), csv_number(r.metrics.log_rmse),
                           csv_number(r.floor.misplaced_energy),
                           csv_number(r.floor.misplaced_floor));
        else
            out += ",,,,,,,,,false\n";
    }
    return out;
}

std::vector<std::string> study_models(const StudySettings& s) {
    std::vector<std::string> model_names = s.models;
    if (model_names.empty() && s.registry_models)
        for (const ModelEntry& e : model_registry())
            if (!e.stochastic) model_names.push_back(e.name);
    for (std::size_t i = 0; i < model_names.size(); ++i) {  // validates
        const std::string& name = model_names[i];
        require_tabulable(*parse_model_spec(name, "--models").entry, "command line", "--models");
        // Two sources of one name would be two rows each in metrics.csv and the rankings.
        if (std::find(model_names.begin(), model_names.begin() + std::ptrdiff_t(i), name) !=
            model_names.begin() + std::ptrdiff_t(i))
            throw InputError("command line", "--models",
                             fmt::format("'{}' is given twice; allowed: each model once", name));
    }
    if (s.ablations) {
        const std::vector<std::string> chosen = model_names;
        for (const std::string& name : chosen) {
            const ModelSpec spec = parse_model_spec(name, "--models");
            if (spec.entry->group != "production" || !spec.assignments.empty()) continue;
            for (const std::string& v : ablation_variants(*spec.entry))
                if (std::find(model_names.begin(), model_names.end(), v) == model_names.end())
                    model_names.push_back(v);
        }
    }
    for (const ExternalModel& e : s.external_models) {
        if (e.name.empty() ||
            std::find(model_names.begin(), model_names.end(), e.name) != model_names.end() ||
            e.name == "reference")
            throw InputError("command line", "--model-table",
                             fmt::format("'{}' cannot name a model table: the name must be new "
                                         "(not empty, 'reference' or a model already compared)",
                                         e.name));
        model_names.push_back(e.name);
    }
    return model_names;
}

void check_external_table(const BinnedTable& table, const HemisphereGrid& grid,
                          const std::vector<double>& theta_i_deg, bool transmits,
                          const std::string& where) {
    if (!(table.grid == grid))
        throw InputError(where, "grid",
                         fmt::format("the table's grid is {} but the study's is {} (--grid)",
                                     table.grid.to_string(), grid.to_string()));
    if (table.theta_i_deg != theta_i_deg)
        throw InputError(
            where, "theta_i",
            fmt::format("the table's incidences are {} but the study's are {} "
                        "(--theta-i): give the table every incidence, in order",
                        fmt::join(table.theta_i_deg, ","), fmt::join(theta_i_deg, ",")));
    if (table.has_transmission && !transmits)
        throw InputError(where, "side",
                         "the table has transmission (T) rows but the stack is opaque: is it "
                         "the table of another stack?");
    for (std::size_t i = 0; i < table.lobes.size(); ++i)
        for (const BinnedLobe& lobe : table.lobes[i])
            for (const Rgbd& f : lobe.f)
                for (int c = 0; c < 3; ++c)
                    if (!std::isfinite(f[c]))
                        throw InputError(
                            where, "f",
                            fmt::format("a value at θi = {}° is not finite", theta_i_deg[i]));
}

ReferenceKey study_reference_key(const StudyConfiguration& config, const StudyIncidence& incidence,
                                 const StudySettings& s) {
    ReferenceKey key =
        reference_key(config.id, config.stack, incidence.theta_i, s.reference, incidence.phi_i);
    key.settings.stokes_tallies = s.reference_stokes && s.reference.transport.polarization &&
                                  !is_spectral_run(config.stack, s.reference);
    return key;
}

std::filesystem::path reference_cache_dir(const std::filesystem::path& out_dir) {
    return out_dir / "cache" / "reference";
}

std::string describe_work(const StudyWork& w) {
    return fmt::format(
        "{} reference pieces simulated, {} model tables computed ({} reused), {} configurations "
        "written ({} unchanged), {} summary files written",
        w.reference_pieces_computed, w.model_tables_computed, w.model_tables_reused,
        w.configurations_written, w.configurations_unchanged, w.files_written);
}

std::string describe_times(const StudyTimes& t, std::size_t slowest) {
    auto span = [](const StudyTimes::Span& s) {
        return fmt::format("{:.1f} / {:.1f}", s.wall, s.cpu);
    };
    std::string out = fmt::format(
        "Time (wall / CPU s): reference {}, model tables {}, comparisons {}, outputs {}, summary "
        "{}",
        span(t.reference), span(t.models), span(t.comparisons), span(t.outputs), span(t.summary));
    if (t.explorer.wall > 0) out += ", explorer page " + span(t.explorer);
    if (t.figures.wall > 0) out += ", figures " + span(t.figures);
    std::vector<std::pair<std::string, StudyTimes::Span>> models = t.per_model;
    std::stable_sort(models.begin(), models.end(),
                     [](const auto& a, const auto& b) { return a.second.cpu > b.second.cpu; });
    if (models.size() > slowest) models.resize(slowest);
    if (!models.empty()) {
        out += "; slowest tables";
        for (std::size_t k = 0; k < models.size(); ++k)
            out += fmt::format("{} {} {}", k == 0 ? ":" : ",", models[k].first,
                               span(models[k].second));
    }
    return out;
}

void check_reference_particles(const StudySettings& s) {
    if (s.reference.particles < 2)
        throw InputError("command line", "--particles",
                         fmt::format("{} is too few: a study simulates each incidence in two "
                                     "halves (its noise floor compares them); give 2 or more",
                                     s.reference.particles));
}

StudyResult run_study(const std::vector<StudyConfiguration>& configs, const StudySettings& s,
                      const std::filesystem::path& out_dir) {
    check_reference_particles(s);
    const std::vector<std::string> model_names = study_models(s);

    StagedOutput probe(out_dir);  // the folder must be writable before any work starts
    std::uint64_t incidences = 0;
    for (const StudyConfiguration& c : configs)
        incidences += study_incidences(c.stack, s.reference).size();
    Progress progress("study", "particles", incidences * s.reference.particles);
    StudyResult result;
    ReferenceLoss lost;
    double reference_seconds = 0;
    for (std::size_t k = 0; k < configs.size(); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::size_t written_before = result.work.configurations_written;
        ConfigResult r = ConfigurationRun(configs[k], s, model_names, out_dir, progress,
                                          result.work, result.times)
                             .run();
        result.rows.insert(result.rows.end(), r.rows.begin(), r.rows.end());
        lost[configs[k].id] = r.lost_microsurface;
        reference_seconds += r.reference_seconds;
        if (!s.quiet) {
            progress.clear_line();
            fmt::print("[{}/{}] {} ({:.1f} s{})\n", k + 1, configs.size(), configs[k].id,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                       result.work.configurations_written > written_before ? "" : ", unchanged");
            std::fflush(stdout);
        }
    }
    progress.finish();

    PhaseTimer summary;
    nlohmann::json sj;
    sj["lamina_version"] = kVersion;
    sj["preset"] = s.preset;
    // The reference's settings (core/setting.h; threads are not the study's), then the kernel as it
    // ran here.
    sj.update(settings_to_json(s.reference));
    sj.erase("threads");
    sj["physics"] = physics_name(s.reference.transport);  // exact, bpb19 or custom
    sj["kernel_description"] = kernel_description(s.reference.kernel);
    sj["models"] = model_names;
    // The family of each model (the explorer groups them): its registry group, "ablations" for a
    // production coat with a flag switched, "external" for a model table or a Python model.
    nlohmann::json groups = nlohmann::json::object();
    for (const std::string& name : model_names) {
        if (std::any_of(s.external_models.begin(), s.external_models.end(),
                        [&](const ExternalModel& e) { return e.name == name; })) {
            groups[name] = "external";
            continue;
        }
        const ModelSpec spec = parse_model_spec(name, "--models");
        groups[name] = spec.assignments.empty() ? spec.entry->group : std::string("ablations");
    }
    sj["model_groups"] = groups;
    sj.update(settings_to_json(s));
    // The reference's simulation time as stored in its pieces: the same on every re-run.
    sj["reference_seconds"] = reference_seconds;
    nlohmann::json list = nlohmann::json::array();
    for (const StudyConfiguration& c : configs) {
        nlohmann::json entry = {
            {"id", c.id},
            {"category", c.category},
            {"parameters", c.parameters},
            {"sides", c.stack.transmits() ? nlohmann::json{"R", "T"} : nlohmann::json{"R"}}};
        // An unfolded configuration: its grid and its incidences (config.json has them too).
        const HemisphereGrid grid = study_grid(c.stack, s.reference);
        if (grid.is_unfolded()) {
            entry["grid"] = grid.to_string();
            entry["incidences"] = nlohmann::json::array();
            for (const StudyIncidence& inc : study_incidences(c.stack, s.reference))
                entry["incidences"].push_back({inc.theta_i, inc.phi_i});
        }
        list.push_back(entry);
    }
    sj["configurations"] = list;
    result.work.files_written += write_file_if_changed(out_dir / "study.json", sj.dump(1) + "\n");
    result.work.files_written +=
        write_file_if_changed(out_dir / "metrics.csv", metrics_csv(result.rows));
    result.findings = compute_findings(configs, s, model_names, result.rows, lost);
    result.work.files_written += write_summary(out_dir, result.findings);
    summary.add_to(result.times.summary);
    return result;
}

}  // namespace lamina
