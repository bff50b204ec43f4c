// The compiled half of `import lamina` (docs/python.md): stacks, the goniophotometer, the models
// and the binned tables, with numpy arrays in and out. The pure-Python package around it
// (src/python/lamina/) adds load_study, the Python model plugins and the documentation strings a
// user reads first.
//
// Conventions are lamina's (docs/notation.md): z is the macro normal, wi the light direction
// (wi.z > 0), wo the viewer (wo.z < 0: transmission), f in 1/sr without the cosine.
// Long computations release the GIL; simulate() checks for Ctrl-C between chunks of particles and
// raises KeyboardInterrupt, and its result is bitwise the CLI's (chunks start at block boundaries,
// whose integer sums add up exactly: simulator/goniophotometer.h).
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/progress.h"
#include "core/spherical.h"
#include "core/table.h"
#include "export/brdf_source.h"
#include "export/merl.h"
#include "export/rgl_bsdf.h"
#include "layers/stack.h"
#include "layers/transport_settings.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "report/explorer.h"
#include "report/figures.h"
#include "simulator/goniophotometer.h"
#include "simulator/output.h"
#include "study/configurations.h"
#include "study/study.h"

#include <fmt/format.h>
#include <omp.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace py = pybind11;

// An object made with `Cls.__new__(Cls)` and never given its `__init__` holds no C++ value, and
// pybind11 would hand its methods uninitialized memory (a crash, or garbage). The casters of the
// module's classes refuse such an object with a TypeError before any method sees it. pybind11
// constructs through `__init__` without these casters (it reaches the value and holder directly).
namespace pybind11::detail {
template <typename T>
class initialized_caster : public type_caster_base<T> {
  public:
    bool load(handle src, bool convert) {
        const type_info* info = get_type_info(typeid(T));
        if (src && info != nullptr && PyObject_TypeCheck(src.ptr(), info->type)) {
            const value_and_holder v_h =
                reinterpret_cast<instance*>(src.ptr())->get_value_and_holder(info, false);
            if (v_h.inst != nullptr && !v_h.holder_constructed())
                throw type_error(
                    "a lamina." +
                    handle(reinterpret_cast<PyObject*>(info->type))
                        .attr("__name__")
                        .cast<std::string>() +
                    " made without its __init__ (by __new__) cannot be used: construct it by "
                    "calling the class");
        }
        return type_caster_base<T>::load(src, convert);
    }
};
template <>
class type_caster<lamina::Stack> : public initialized_caster<lamina::Stack> {};
template <>
class type_caster<lamina::BinnedTable> : public initialized_caster<lamina::BinnedTable> {};
}  // namespace pybind11::detail

namespace lamina {
namespace {

PyObject* g_input_error = nullptr;  // lamina.InputError, a subclass of ValueError

// How deep an argument may nest: a stack nests five levels (stack, layers, layer, interface, RGB
// array), as the stack files' reader allows 32; deeper, or a container holding itself, is refused
// before anything recurses through it.
constexpr int kMaxArgumentDepth = 32;

/// Where in `o` (dicts, lists, tuples, numpy values) the first NaN or infinity (or an integer
/// beyond a double) is, as a JSON pointer from `at`; empty if nowhere. Past kMaxArgumentDepth an
/// InputError naming `where`.
std::string non_finite_at(py::handle o, const std::string& at, const std::string& where,
                          int depth = 0) {
    if (depth > kMaxArgumentDepth)
        throw InputError(where, where == "arguments" ? at.substr(1) : at,
                         fmt::format("nested more than {} levels deep (or containing itself)",
                                     kMaxArgumentDepth));
    if (py::isinstance<py::float_>(o)) return std::isfinite(o.cast<double>()) ? "" : at;
    if (py::isinstance<py::int_>(o) && !py::isinstance<py::bool_>(o)) {
        // An integer beyond a double's range (10**400) is no number lamina can take.
        const double v = PyLong_AsDouble(o.ptr());
        if (v == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            return at;
        }
        return "";
    }
    if (py::isinstance<py::dict>(o)) {
        for (const auto& [key, value] : o.cast<py::dict>())
            if (std::string r = non_finite_at(value, at + "/" + py::str(key).cast<std::string>(),
                                              where, depth + 1);
                !r.empty())
                return r;
        return "";
    }
    if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o)) {
        std::size_t i = 0;
        for (py::handle value : o)
            if (std::string r =
                    non_finite_at(value, at + "/" + std::to_string(i++), where, depth + 1);
                !r.empty())
                return r;
        return "";
    }
    if (py::hasattr(o, "tolist") && !py::isinstance<py::str>(o))
        return non_finite_at(o.attr("tolist")(), at, where, depth + 1);
    return "";
}

/// `obj` as JSON; a NaN or infinity in it is an InputError naming `where` and its place.
nlohmann::json json_of(py::handle obj, const std::string& where = "arguments") {
    // A stack dict's place as a JSON pointer (/layers/0/interface/eta); an argument's by its
    // name (theta_i/0), as the other argument errors.
    if (const std::string at = non_finite_at(obj, "", where); !at.empty())
        throw InputError(where, where == "arguments" ? at.substr(1) : at,
                         "not a finite number; allowed: finite numbers");
    const py::object dumps = py::module_::import("json").attr("dumps");
    // numpy arrays and scalars as lists and numbers; tuples are lists already.
    const py::cpp_function plain([](py::handle o) -> py::object {
        if (py::hasattr(o, "tolist")) return o.attr("tolist")();
        throw py::type_error("not a JSON value: " + py::repr(o).cast<std::string>());
    });
    return nlohmann::json::parse(
        dumps(obj, py::arg("allow_nan") = false, py::arg("default") = plain).cast<std::string>());
}

py::object python_of(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

/// A Stack, a dict in the stack format (docs/stack-format.md) or a path to a stack file.
Stack stack_of(py::handle source) {
    if (py::isinstance<Stack>(source)) return source.cast<Stack>();
    if (py::isinstance<py::dict>(source))
        return stack_from_json(json_of(source, "<dict>"), "<dict>");
    const py::object os = py::module_::import("os");
    if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__"))
        return load_stack(os.attr("fspath")(source).cast<std::string>());
    throw py::type_error("a stack is a lamina.Stack, a dict in the stack format, or a file path");
}

HemisphereGrid grid_of(const std::pair<int, int>& grid) {
    return HemisphereGrid::parse(fmt::format("{}x{}", grid.first, grid.second), "grid");
}

/// Whether `x` is one value rather than a sequence of them: not iterable (a Python or numpy
/// number), or a numpy array of no dimension (which has __iter__ but cannot be iterated); a string
/// is one value too.
bool is_one_value(py::handle x) {
    if (py::isinstance<py::str>(x) || py::isinstance<py::bytes>(x)) return true;
    if (!py::hasattr(x, "__iter__")) return true;
    return py::hasattr(x, "ndim") && py::int_(x.attr("ndim")).cast<int>() == 0;
}

/// Whether `x` is a truth value (Python's or numpy's), which is not a number of degrees.
bool is_truth_value(py::handle x) {
    if (py::isinstance<py::bool_>(x)) return true;
    return py::hasattr(x, "dtype") &&
           py::str(x.attr("dtype").attr("kind")).cast<std::string>() == "b";
}

/// A number of degrees from Python (numpy's numbers too); a string or a truth value is not one.
double degrees_of(py::handle t, const std::string& at) {
    if (py::isinstance<py::str>(t) || py::isinstance<py::bytes>(t) || is_truth_value(t) ||
        !(py::isinstance<py::float_>(t) || py::isinstance<py::int_>(t) ||
          py::hasattr(t, "__float__")))
        throw InputError(
            "arguments", at,
            fmt::format("expected a number of degrees, got {}", py::repr(t).cast<std::string>()));
    return py::float_(py::reinterpret_borrow<py::object>(t)).cast<double>();
}

/// One number of degrees, or a sequence of them (`at`/0, `at`/1, ... in messages), unchecked.
std::vector<double> degrees_list(py::handle x, const std::string& at) {
    std::vector<double> out;
    if (is_one_value(x))
        out.push_back(degrees_of(x, at));
    else
        for (py::handle t : py::iter(x))
            out.push_back(degrees_of(t, fmt::format("{}/{}", at, out.size())));
    return out;
}

std::vector<double> incidences_of(py::handle theta_i) {
    std::vector<double> out = degrees_list(theta_i, "theta_i");
    if (out.empty()) throw InputError("arguments", "theta_i", "at least one incidence is needed");
    check_incidence_list(out, "arguments", "theta_i");  // in range, each once (as the CLI's)
    return out;
}

/// [n_inc, n_sides, n_theta, n_phi, 3] of the table's f (se: false) or se (true).
py::array_t<double> lobes_array(const BinnedTable& t, bool se) {
    const std::size_t n_inc = t.theta_i_deg.size();
    std::vector<Side> sides;
    if (t.has_reflection) sides.push_back(Side::Reflection);
    if (t.has_transmission) sides.push_back(Side::Transmission);
    py::array_t<double> a({n_inc, sides.size(), std::size_t(t.grid.n_theta()),
                           std::size_t(t.grid.n_phi()), std::size_t(3)});
    double* p = a.mutable_data();
    for (std::size_t i = 0; i < n_inc; ++i)
        for (Side side : sides) {
            const BinnedLobe& lobe = t.lobe(i, side);
            const std::vector<Rgbd>& v = se ? lobe.se : lobe.f;
            for (std::size_t j = 0; j < t.grid.size(); ++j)
                for (int c = 0; c < 3; ++c)
                    *p++ = j < v.size() ? v[j][c] : 0.0;
        }
    return a;
}

py::list sides_of(const BinnedTable& t) {
    py::list out;
    if (t.has_reflection) out.append("R");
    if (t.has_transmission) out.append("T");
    return out;
}

py::array_t<double> edges_deg(int n, double range) {
    py::array_t<double> a(n + 1);
    for (int k = 0; k <= n; ++k)
        a.mutable_data()[k] = range * k / n;
    return a;
}

// ---- simulate --------------------------------------------------------------------------------

SimulationResult simulate_interruptible(const Stack& stack, const SimulationSettings& s,
                                        bool show_progress) {
    validate_settings(s);
    const int threads = s.threads > 0 ? s.threads : omp_get_max_threads();
    // Chunks of whole blocks: their integer sums add up to one run's, bit for bit. Each chunk
    // costs a set-up (tallies allocated and merged), so chunks double while they take under
    // 0.2 s: Ctrl-C is then seen within about half a second.
    std::uint64_t chunk = kParticlesPerBlock * 16 * std::uint64_t(threads);
    SimulationSums total = zero_sums(stack, s);
    std::unique_ptr<Progress> progress;
    if (show_progress)
        progress = std::make_unique<Progress>(fmt::format("simulate {}", stack.name), "particles",
                                              s.particles * s.theta_i_deg.size());
    const auto start = std::chrono::steady_clock::now();
    for (std::uint64_t first = 0, next = chunk; first < s.particles; first = next) {
        const auto chunk_start = std::chrono::steady_clock::now();
        SimulationSettings part = s;
        part.first_particle = s.first_particle + first;
        part.particles = std::min(chunk, s.particles - first);  // a multiple of blocks
        SimulationSums sums;
        {
            py::gil_scoped_release release;
            sums = simulate_sums(stack, part, [&](std::uint64_t n) {
                if (progress) progress->advance(n);
            });
        }
        for (std::size_t i = 0; i < total.incidences.size(); ++i) {
            total.incidences[i].add(sums.incidences[i]);
            total.incidence_seconds[i] += sums.incidence_seconds[i];
        }
        total.threads_used = sums.threads_used;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
        const double took =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - chunk_start).count();
        if (took < 0.2 && chunk < (std::uint64_t(1) << 40)) chunk *= 2;
        next = first + part.particles;
    }
    if (progress) progress->finish();
    total.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return finalize_simulation(stack, s, total);
}

struct PySimulation {
    Stack stack;
    SimulationResult result;
};

// ---- models ----------------------------------------------------------------------------------

struct PyModel {
    std::string name;
    Stack stack;
    ModelOptions options;
    std::unique_ptr<Model> model;
};

}  // namespace
}  // namespace lamina

namespace pybind11::detail {
template <>
class type_caster<lamina::PySimulation> : public initialized_caster<lamina::PySimulation> {};
template <>
class type_caster<lamina::PyModel> : public initialized_caster<lamina::PyModel> {};
}  // namespace pybind11::detail

namespace lamina {
namespace {

std::string option_text(py::handle v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "on" : "off";
    return py::str(v).cast<std::string>();
}

/// Cosines closer to the horizon than this are taken on it (z = 0: grazing). The models multiply
/// and square cosines (4 |cos θi| |cos θo| under a BRDF, a half vector's length), which underflow
/// to 0 below about 1e-162 and turned such directions' values into NaN; no angle in degrees comes
/// that close (cos 90° is 6e-17 in double).
constexpr double kGrazingCosine = 1e-100;

/// A direction argument (`name`; `which`, "" or "direction 3 " for an array's): a finite unit
/// vector to 1e-6, or an InputError; within kGrazingCosine of the horizon, on it.
Vec3d unit_direction(double x, double y, double z, const char* name, const std::string& which) {
    const double len = std::sqrt(x * x + y * y + z * z);
    if (!std::isfinite(len) || std::abs(len - 1) > 1e-6)
        throw InputError(
            "arguments", name,
            fmt::format("{}({}, {}, {}): directions must be finite unit vectors", which, x, y, z));
    if (std::abs(z) < kGrazingCosine) z = 0;
    return {x, y, z};
}

/// Directions as an [n, 3] C-contiguous float64 array, broadcast against each other; the shape of
/// the leading axes comes back in `shape`.
std::vector<py::array_t<double, py::array::c_style | py::array::forcecast>> broadcast_directions(
    const std::vector<std::pair<const char*, py::handle>>& inputs,
    std::vector<py::ssize_t>& shape) {
    const py::object np = py::module_::import("numpy");
    py::list arrays;
    for (const auto& [name, obj] : inputs) {
        py::array a = np.attr("asarray")(obj, py::arg("dtype") = "float64");
        if (a.ndim() < 1 || a.shape(a.ndim() - 1) != 3)
            throw InputError("arguments", name,
                             "expected an array of 3-vectors (last axis of length 3)");
        arrays.append(a);
    }
    py::tuple b = np.attr("broadcast_arrays")(*arrays);
    std::vector<py::array_t<double, py::array::c_style | py::array::forcecast>> out;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
        py::array a = b[k];
        shape.assign(a.shape(), a.shape() + a.ndim() - 1);
        out.push_back(np.attr("ascontiguousarray")(a).attr("reshape")(-1, 3));
        const double* d = out.back().data();
        for (py::ssize_t n = 0; n < out.back().shape(0); ++n)
            unit_direction(d[3 * n], d[3 * n + 1], d[3 * n + 2], inputs[k].first,
                           fmt::format("direction {} is ", n));
    }
    return out;
}

py::array_t<double> shaped(std::vector<py::ssize_t> shape, py::ssize_t last) {
    if (last > 0) shape.push_back(last);
    return py::array_t<double>(shape);
}

Vec3d vec_at(const double* d, py::ssize_t n) {
    return {d[3 * n], d[3 * n + 1], d[3 * n + 2]};
}

/// Direction n of a checked array (broadcast_directions), on the horizon within kGrazingCosine.
Vec3d direction_at(const double* d, py::ssize_t n) {
    const double z = d[3 * n + 2];
    return {d[3 * n], d[3 * n + 1], std::abs(z) < kGrazingCosine ? 0.0 : z};
}

// f(wi, wo) for every broadcast pair of directions, `channels` values each (0: a scalar), in
// parallel without the GIL; f writes the pair's values; pairs with wi below the surface are 0.
template <typename F>
py::array_t<double> over_direction_pairs(py::handle wi_obj, py::handle wo_obj, int channels,
                                         F&& f) {
    std::vector<py::ssize_t> shape;
    auto arrays = broadcast_directions({{"wi", wi_obj}, {"wo", wo_obj}}, shape);
    const double *wi = arrays[0].data(), *wo = arrays[1].data();
    const py::ssize_t n = arrays[0].shape(0);
    py::array_t<double> out = shaped(shape, channels);
    double* v = out.mutable_data();
    const int stride = std::max(channels, 1);
    {
        py::gil_scoped_release release;
#pragma omp parallel for schedule(static)
        for (py::ssize_t k = 0; k < n; ++k) {
            const Vec3d a = direction_at(wi, k);
            if (a.z > 0)
                f(a, direction_at(wo, k), v + stride * k);
            else
                std::fill(v + stride * k, v + stride * (k + 1), 0.0);
        }
    }
    return out;
}

py::array_t<double> model_eval(const PyModel& m, py::handle wi_obj, py::handle wo_obj) {
    return over_direction_pairs(wi_obj, wo_obj, 3,
                                [&](const Vec3d& wi, const Vec3d& wo, double* out) {
                                    const Rgbd v = m.model->eval(wi, wo);
                                    for (int c = 0; c < 3; ++c)
                                        out[c] = v[c];
                                });
}

void require_sampling(const PyModel& m) {
    if (!m.model->has_sampling())
        throw py::attribute_error(fmt::format(
            "model '{}' has no importance sampling (Model.has_sampling is False)", m.name));
}

py::tuple model_sample(const PyModel& m, py::handle wi_obj, py::handle u_obj) {
    require_sampling(m);
    const py::object np = py::module_::import("numpy");
    py::array u_in = np.attr("asarray")(u_obj, py::arg("dtype") = "float64");
    if (u_in.ndim() < 1 || u_in.shape(u_in.ndim() - 1) != 3)
        throw InputError("arguments", "u", "expected an array of 3 uniforms in [0, 1) per sample");
    std::vector<py::ssize_t> shape;
    // The uniforms are not directions: broadcast them with wi by hand.
    py::tuple b = np.attr("broadcast_arrays")(np.attr("asarray")(wi_obj, "float64"), u_in);
    auto arrays = broadcast_directions({{"wi", b[0]}}, shape);
    py::array_t<double, py::array::c_style | py::array::forcecast> u =
        np.attr("ascontiguousarray")(b[1]).attr("reshape")(-1, 3);
    const double *wi = arrays[0].data(), *ud = u.data();
    const py::ssize_t n = arrays[0].shape(0);
    for (py::ssize_t k = 0; k < 3 * n; ++k)
        if (!(ud[k] >= 0 && ud[k] < 1))
            throw InputError("arguments", "u", fmt::format("{} is outside [0, 1)", ud[k]));
    py::array_t<double> wo = shaped(shape, 3), weight = shaped(shape, 3), pdf = shaped(shape, 0);
    py::array_t<bool> valid(shape);
    double *wo_p = wo.mutable_data(), *w_p = weight.mutable_data(), *pdf_p = pdf.mutable_data();
    bool* ok = valid.mutable_data();
    {
        py::gil_scoped_release release;
#pragma omp parallel for schedule(static)
        for (py::ssize_t k = 0; k < n; ++k) {
            const Vec3d a = direction_at(wi, k);
            const std::optional<ModelSample> s =
                a.z > 0 ? m.model->sample(a, vec_at(ud, k)) : std::nullopt;
            ok[k] = bool(s);
            const ModelSample v = s.value_or(ModelSample{Vec3d(0, 0, 0), Rgbd(0.0), 0.0});
            for (int c = 0; c < 3; ++c) {
                wo_p[3 * k + c] = c == 0 ? v.wo.x : c == 1 ? v.wo.y : v.wo.z;
                w_p[3 * k + c] = v.weight[c];
            }
            pdf_p[k] = v.pdf;
        }
    }
    return py::make_tuple(wo, weight, pdf, valid);
}

py::array_t<double> model_pdf(const PyModel& m, py::handle wi_obj, py::handle wo_obj) {
    require_sampling(m);
    return over_direction_pairs(
        wi_obj, wo_obj, 0,
        [&](const Vec3d& wi, const Vec3d& wo, double* out) { *out = m.model->pdf(wi, wo); });
}

py::dict support_of(const Support& s) {
    py::dict d;
    d["brdf"] = s.brdf;
    d["btdf"] = s.btdf;
    d["reason"] = s.reason;
    return d;
}

/// A table from numpy: f [n_inc, n_sides, n_theta, n_phi, 3] for `sides` ("R", "T"), se = 0;
/// `unfolded`: the φ bins cover [0°, 360°) (n_phi even: the unfolded grid of n_phi / 2).
BinnedTable table_from_arrays(py::array_t<double, py::array::c_style | py::array::forcecast> f,
                              py::handle theta_i_arg, const std::vector<std::string>& sides,
                              bool unfolded) {
    const std::vector<double> theta_i = degrees_list(theta_i_arg, "theta_i");
    if (f.ndim() != 5 || f.shape(4) != 3 || std::size_t(f.shape(0)) != theta_i.size() ||
        std::size_t(f.shape(1)) != sides.size())
        throw InputError("arguments", "f",
                         "expected f of shape [incidence, side, θ bin, φ bin, 3] matching theta_i "
                         "and sides");
    // As a table read from its CSV, which has at least one row.
    if (theta_i.empty())
        throw InputError("arguments", "theta_i", "at least one incidence is needed");
    if (sides.empty()) throw InputError("arguments", "sides", "at least one side, 'R' or 'T'");
    bool r = false, t = false;
    for (const std::string& side : sides) {
        if (side != "R" && side != "T") throw InputError("arguments", "sides", "'R' or 'T'");
        (side == "R" ? r : t) = true;
    }
    if (sides.size() == 2 && !(sides[0] == "R" && sides[1] == "T"))
        throw InputError("arguments", "sides", "use ['R'], ['T'] or ['R', 'T'] (in that order)");
    // As a table read from its CSV: each θi in [0, 90), once on a folded grid (an unfolded table
    // may hold one θi at several azimuths, the incidences of a brushed configuration).
    std::vector<double> incidences = theta_i;
    if (unfolded)
        for (double t : incidences)
            check_incidence(t, "arguments", "theta_i");
    else
        check_incidence_list(incidences, "arguments", "theta_i");
    if (unfolded && f.shape(3) % 2 != 0)
        throw InputError("arguments", "f",
                         "an unfolded table has an even number of φ bins over [0°, 360°)");
    const HemisphereGrid grid = unfolded
                                    ? grid_of({int(f.shape(2)), int(f.shape(3) / 2)}).unfolded()
                                    : grid_of({int(f.shape(2)), int(f.shape(3))});
    BinnedTable table = BinnedTable::zeros(grid, incidences, r, t);
    const double* p = f.data();
    for (std::size_t i = 0; i < theta_i.size(); ++i)
        for (const std::string& side : sides) {
            BinnedLobe& lobe = table.lobe(i, side == "R" ? Side::Reflection : Side::Transmission);
            for (std::size_t j = 0; j < grid.size(); ++j)
                for (int c = 0; c < 3; ++c) {
                    const double v = *p++;
                    if (!(std::abs(v) <= kMaxBinValue))  // NaN too; as BinnedTable::from_csv
                        throw InputError("arguments", "f",
                                         fmt::format("a value at θi = {}° is {}: allowed finite, "
                                                     "within ±{:g} (1/sr)",
                                                     theta_i[i], v, kMaxBinValue));
                    lobe.f[j][c] = v;
                }
        }
    return table;
}

/// lamina.study / lamina.compare: run_study with Python models as external tables, then the
/// explorer and the figures. `externals`: [(name, fn(config_id, stack, theta_i, phi_i) -> Table |
/// None)], theta_i and phi_i the configuration's incidences (degrees, in order).
void run_study_py(py::list configs_in, py::dict settings, py::list externals,
                  const std::filesystem::path& out, bool figures) {
    std::vector<StudyConfiguration> configs;
    std::set<std::string> ids;
    for (py::handle c : configs_in) {
        StudyConfiguration sc;
        sc.id = c["id"].cast<std::string>();
        sc.category = c["category"].cast<std::string>();
        const std::string at = fmt::format("configs[{}]", configs.size());
        check_configuration_id(sc.id, "arguments", at + ".id");
        if (!ids.insert(configuration_id_key(sc.id)).second)
            throw InputError("arguments", at + ".id", fmt::format("'{}' {}", sc.id, kIdTwice));
        check_study_label(sc.category, "category", "arguments", at + ".category");
        sc.stack = stack_of(c["stack"]);
        sc.parameters = describe_parameters(sc.stack);
        configs.push_back(std::move(sc));
    }
    // settings: {"reference": the goniophotometer's settings, "study": the study's, "preset",
    // "models", "quiet", "registry_models"}: read by the settings' own codecs (core/setting.h).
    StudySettings s;
    settings_from_json(s.reference, json_of(settings["reference"]), "arguments");
    settings_from_json(s, json_of(settings["study"]), "arguments");
    s.preset = settings["preset"].cast<std::string>();
    s.models = settings["models"].cast<std::vector<std::string>>();
    s.quiet = settings["quiet"].cast<bool>();
    s.registry_models = settings["registry_models"].cast<bool>();
    for (py::handle e : externals) {
        ExternalModel m;
        m.name = e[py::int_(0)].cast<std::string>();
        check_study_label(m.name, "model name", "arguments", "models");
        m.source = "Python model '" + m.name + "'";
        py::object fn = py::reinterpret_borrow<py::object>(e[py::int_(1)]);
        m.unfolded = true;  // a Python model is evaluated at any wi
        m.table = [fn](const StudyConfiguration& c, const std::vector<StudyIncidence>& incidences,
                       const HemisphereGrid&) {
            py::gil_scoped_acquire gil;
            std::vector<double> theta_i, phi_i;
            for (const StudyIncidence& inc : incidences) {
                theta_i.push_back(inc.theta_i);
                phi_i.push_back(inc.phi_i);
            }
            py::object t = fn(c.id, c.stack, theta_i, phi_i);
            if (t.is_none()) {
                BinnedTable none;
                none.has_reflection = false;
                return none;
            }
            return t.cast<BinnedTable>();
        };
        s.external_models.push_back(std::move(m));
    }
    {
        py::gil_scoped_release release;
        run_study(configs, s, out);
        // Without tables (tables="none") there is no page to draw, as on the command line.
        if (s.tables != TablesFormat::None) write_explorer(out);
        if (figures) {
            try {
                write_figures(out);
            } catch (const InputError& e) {
                py::gil_scoped_acquire gil;
                PyErr_WarnEx(PyExc_RuntimeWarning,
                             (std::string("figures not written: ") + e.what()).c_str(), 1);
            }
        }
    }
}

// lamina.InputError (InputError's file, field and problem), the defaults Python reads.
void bind_errors(py::module_& m) {
    g_input_error = PyErr_NewExceptionWithDoc(
        "lamina.InputError",
        "Bad input, as the lamina CLI reports it: .file (or 'command line', 'arguments', "
        "'<dict>'), .field (a JSON pointer or an argument name) and .problem (what is wrong and "
        "what is allowed).",
        PyExc_ValueError, nullptr);
    m.attr("InputError") = py::handle(g_input_error);
    m.attr("DEFAULT_THETA_I") = py::cast(default_incidences_deg());
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            // A check shared with the CLI names its option ("command line", "--only"); from
            // Python it is the argument of that name ("arguments", "only"), and the CLI's other
            // arguments (a model's "name", its "options") are Python's too.
            const bool command_line = e.where() == "command line";
            std::string field = e.field();
            if (command_line && field.starts_with("--")) {
                field = field.substr(2);
                std::replace(field.begin(), field.end(), '-', '_');
            }
            const InputError named = command_line ? InputError("arguments", field, e.problem()) : e;
            // A message may quote bytes of the input that are not UTF-8 (a stack file in
            // Latin-1): they are written as \xNN escapes rather than failing the conversion.
            auto text = [](const std::string& bytes) {
                return py::reinterpret_steal<py::str>(PyUnicode_DecodeUTF8(
                    bytes.data(), Py_ssize_t(bytes.size()), "backslashreplace"));
            };
            py::object exc = py::handle(g_input_error)(text(named.what()));
            exc.attr("file") = text(named.where());
            exc.attr("field") = text(named.field());
            exc.attr("problem") = text(named.problem());
            PyErr_SetObject(g_input_error, exc.ptr());
        }
    });

    m.attr("kernel_description") = py::cpp_function([](const std::string& k) {
        return kernel_description(SettingCodec<Kernel>::from_text(k, {.name = "kernel", .help = ""},
                                                                  "arguments", "kernel"));
    });
}

// lamina.Stack.
void bind_stack(py::module_& m) {
    py::class_<Stack>(m, "Stack", "A layer stack (docs/stack-format.md)")
        .def(py::init([](py::handle source) { return stack_of(source); }), py::arg("source"),
             "From a dict in the stack format or a path to a stack JSON file; lamina.InputError "
             "names the file, the field and what is allowed")
        .def_property_readonly("name", [](const Stack& s) { return s.name; })
        .def_property_readonly("transmits", &Stack::transmits,
                               "True for slabs (a dielectric base): the stack has a BTDF")
        .def(
            "to_dict", [](const Stack& s) { return python_of(stack_to_json(s)); },
            "The canonical stack JSON as a dict (Stack(s.to_dict()) == s)")
        .def("describe", [](const Stack& s) { return describe(s); })
        .def("__eq__", [](const Stack& a, const Stack& b) { return a == b; })
        .def("__repr__", [](const Stack& s) { return "<lamina.Stack " + describe(s) + ">"; });
}

// lamina.Table: binned tables (the brdf.csv format) as numpy arrays.
void bind_table(py::module_& m) {
    py::class_<BinnedTable>(m, "Table",
                            "Binned BRDF/BTDF: cos-weighted bin averages, the brdf.csv format")
        .def_static(
            "from_csv",
            [](const std::filesystem::path& path) {
                return BinnedTable::from_csv(
                    read_file_bounded(path, kMaxTableFileBytes, "the table"), path.string());
            },
            py::arg("path"))
        .def_static("from_arrays", &table_from_arrays, py::arg("f"), py::arg("theta_i"),
                    py::arg("sides") = std::vector<std::string>{"R"}, py::arg("unfolded") = false,
                    "A table from f [incidence, side, θ bin, φ bin, 3] (1/sr, cos-weighted bin "
                    "averages; se = 0), e.g. to write a --model-table CSV with to_csv(); "
                    "unfolded: the φ bins cover [0°, 360°) (an anisotropic stack, φi ≠ 0)")
        .def_property_readonly(
            "f", [](const BinnedTable& t) { return lobes_array(t, false); },
            "f [incidence, side, θ bin, φ bin, channel], 1/sr")
        .def_property_readonly(
            "se", [](const BinnedTable& t) { return lobes_array(t, true); },
            "standard errors, same shape (0 for deterministic models)")
        .def_property_readonly("theta_i", [](const BinnedTable& t) { return t.theta_i_deg; })
        .def_property_readonly("sides", [](const BinnedTable& t) { return sides_of(t); })
        .def_property_readonly(
            "grid",
            [](const BinnedTable& t) { return std::make_pair(t.grid.n_theta(), t.grid.n_phi()); })
        .def_property_readonly(
            "theta_edges", [](const BinnedTable& t) { return edges_deg(t.grid.n_theta(), 90); },
            "θ bin edges, degrees")
        .def_property_readonly(
            "phi_edges",
            [](const BinnedTable& t) { return edges_deg(t.grid.n_phi(), t.grid.phi_span_deg()); },
            "φ bin edges, degrees (folded: each bin covers ±φ)")
        .def_property_readonly(
            "projected_solid_angle",
            [](const BinnedTable& t) {
                py::array_t<double> a({t.grid.n_theta(), t.grid.n_phi()});
                for (std::size_t j = 0; j < t.grid.size(); ++j)
                    a.mutable_data()[j] = t.grid.projected_solid_angle(j);
                return a;
            },
            "Ω⊥ of each bin [θ bin, φ bin], sr (both folded halves)")
        .def("to_csv", &BinnedTable::to_csv, "The brdf.csv text")
        .def("__repr__", [](const BinnedTable& t) {
            return fmt::format("<lamina.Table {} incidences, sides {}, grid {}>",
                               t.theta_i_deg.size(),
                               t.has_reflection && t.has_transmission ? "R, T"
                               : t.has_reflection                     ? "R"
                                                                      : "T",
                               t.grid.to_string());
        });
}

// lamina.simulate: the goniophotometer and its settings.
void bind_simulation(py::module_& m) {
    py::class_<PySimulation>(m, "SimulationResult", "A goniophotometer run (lamina simulate)")
        .def_property_readonly("stack", [](const PySimulation& r) { return r.stack; })
        .def_property_readonly("table", [](const PySimulation& r) { return r.result.table; })
        .def_property_readonly(
            "f", [](const PySimulation& r) { return lobes_array(r.result.table, false); })
        .def_property_readonly(
            "se", [](const PySimulation& r) { return lobes_array(r.result.table, true); })
        .def_property_readonly("theta_i",
                               [](const PySimulation& r) { return r.result.settings.theta_i_deg; })
        .def_property_readonly("sides",
                               [](const PySimulation& r) { return sides_of(r.result.table); })
        .def_property_readonly(
            "theta_edges",
            [](const PySimulation& r) { return edges_deg(r.result.settings.grid.n_theta(), 90); })
        .def_property_readonly("phi_edges",
                               [](const PySimulation& r) {
                                   return edges_deg(r.result.table.grid.n_phi(),
                                                    r.result.table.grid.phi_span_deg());
                               })
        .def_property_readonly(
            "energy",
            [](const PySimulation& r) {
                py::dict d;
                const std::size_t n = r.result.incidences.size();
                auto add = [&](const char* name, auto get) {
                    py::array_t<double> a({n, std::size_t(3)});
                    for (std::size_t i = 0; i < n; ++i)
                        for (int c = 0; c < 3; ++c)
                            a.mutable_data()[3 * i + c] = get(r.result.incidences[i].budget)[c];
                    d[name] = a;
                };
                for (int t = 0; t < kBudgetTerms; ++t)
                    add(kBudgetTermNames[t], [t](const EnergyBudget& b) { return b.term[t]; });
                add("reflected_se", [](const EnergyBudget& b) { return b.reflected_se; });
                add("transmitted_se", [](const EnergyBudget& b) { return b.transmitted_se; });
                return d;
            },
            "Energy budget terms, each [incidence, channel] (fractions of the incident flux)")
        .def_property_readonly(
            "spectral",
            [](const PySimulation& r) -> py::object {
                const SpectralTables& sp = r.result.spectral;
                if (sp.bin_edges_nm.empty()) return py::none();
                const std::size_t bins = sp.bin_edges_nm.size() - 1,
                                  n_inc = r.result.settings.theta_i_deg.size(),
                                  n_theta = std::size_t(r.result.table.grid.n_theta()),
                                  n_phi = sp.n_directions / n_theta;
                auto tables = [&](const std::vector<double>& v) {
                    py::array_t<double> a({n_inc, std::size_t(sp.sides), n_theta, n_phi, bins});
                    std::copy(v.begin(), v.end(), a.mutable_data());
                    return a;
                };
                py::array_t<double> energy({n_inc, bins, std::size_t(kBudgetTerms + 2)});
                for (std::size_t i = 0; i < sp.budget.size(); ++i)
                    std::copy(sp.budget[i].begin(), sp.budget[i].end(),
                              energy.mutable_data() + i * (kBudgetTerms + 2));
                py::dict d;
                d["bin_edges_nm"] = sp.bin_edges_nm;
                d["f"] = tables(sp.f);
                d["se"] = tables(sp.se);
                d["xyz"] = lobes_array(sp.xyz, false);
                d["xyz_se"] = lobes_array(sp.xyz, true);
                d["energy"] = energy;
                return d;
            },
            "A spectral run's tables (None for an RGB run; docs/formats.md): bin_edges_nm; f, se "
            "[incidence, side, θ bin, φ bin, wavelength bin] (the sides of `sides`); xyz, xyz_se "
            "[..., 3] (CIE 1931 XYZ under D65); energy [incidence, wavelength bin, term] (the "
            "budget terms, then the standard errors of R and T). f and se above are the linear "
            "sRGB projection.")
        .def_property_readonly(
            "info", [](const PySimulation& r) { return python_of(result_json(r.stack, r.result)); },
            "result.json as a dict")
        .def(
            "write",
            [](const PySimulation& r, const std::filesystem::path& dir) {
                write_simulation(dir, r.stack, r.result, {}, "dir");
            },
            py::arg("dir"), "Writes DIR/{brdf.csv,energy.csv,result.json} as lamina simulate does")
        .def("__repr__", [](const PySimulation& r) {
            return fmt::format("<lamina.SimulationResult {}: {} incidences × {} particles>",
                               r.stack.name, r.result.settings.theta_i_deg.size(),
                               r.result.settings.particles);
        });

    // The goniophotometer's settings and their defaults, by name (core/setting.h): Python's
    // keyword arguments of simulate, compare and study.
    m.attr("SIMULATION_SETTINGS") = python_of(settings_to_json(SimulationSettings{}));
    // The most bins along θ and along φ a grid may have (core/grid.h, as --grid takes).
    m.attr("GRID_MAX_COUNT") = HemisphereGrid::kMaxCount;
    // The named references (layers/transport_settings.h): the settings each one sets.
    nlohmann::json physics = nlohmann::json::object();
    for (const auto& n : enum_names(ReferencePhysics{})) {
        TransportSettings t;
        apply_physics(n.value, t);
        physics[n.text] = {{"polarization", t.polarization},
                           {"microsurface", enum_text(t.microsurface)}};
    }
    m.attr("REFERENCE_PHYSICS") = python_of(physics);
    m.def(
        "_simulate",
        [](py::handle stack_obj, py::dict settings, bool progress) {
            SimulationSettings s;
            settings_from_json(s, json_of(settings), "arguments");
            PySimulation r{stack_of(stack_obj), {}};
            r.result = simulate_interruptible(r.stack, s, progress);
            return r;
        },
        py::arg("stack"), py::arg("settings"), py::arg("progress"));
    m.def("_preset_particles", &preset_particles, py::arg("preset"));
}

// lamina.export: .bsdf, MERL and .npz files.
void bind_export(py::module_& m) {
    m.def(
        "_export",
        [](py::object source, const std::filesystem::path& path, const std::string& format,
           std::vector<double> theta_i, std::optional<int> resolution,
           const std::string& description, std::optional<int> azimuths) {
            // source: a Model or a Table (its reflection side).
            BrdfSource brdf;
            if (py::isinstance<PyModel>(source)) {
                const PyModel& pm = source.cast<const PyModel&>();
                const ModelEntry& entry = find_model(pm.name, "name");
                require_tabulable(entry, "arguments", "source");
                auto model = std::shared_ptr<const Model>(entry.make(pm.stack, pm.options));
                brdf = model_brdf(model, pm.stack, pm.name);
            } else {
                brdf = table_brdf(source.cast<const BinnedTable&>(), "table", "table");
            }
            std::string bytes;
            {
                py::gil_scoped_release release;
                if (format == "bsdf") {
                    RglOptions o;
                    o.theta_i_deg = theta_i;
                    if (resolution) o.resolution = *resolution;  // else RglOptions' default
                    if (azimuths) o.azimuths = *azimuths;
                    o.description = description;
                    const TensorFile file = rgl_bsdf(brdf, o);
                    check_rgl_bsdf(file, path.string());
                    bytes = tensor_file_bytes(file);
                } else if (format == "merl") {
                    bytes = merl_binary(brdf);
                } else {
                    throw InputError("arguments", "format", "'bsdf' or 'merl'");
                }
                write_file_atomic(path, bytes);
            }
        },
        py::arg("source"), py::arg("path"), py::arg("format"), py::arg("theta_i"),
        py::arg("resolution"), py::arg("description"), py::arg("azimuths"));
}

// lamina.study and lamina.compare, with Python models as external tables.
void bind_study(py::module_& m) {
    m.def("_table_from_arrays", &table_from_arrays, py::arg("f"), py::arg("theta_i"),
          py::arg("sides"), py::arg("unfolded") = false);
    // Whether the goniophotometer tabulates this stack lit from these azimuths (degrees) on the
    // unfolded grid (simulation_grid's rule: an anisotropic stack, or some φi ≠ 0).
    m.def(
        "_unfolded",
        [](const Stack& stack, const std::vector<double>& phi_i) {
            SimulationSettings s;
            for (double phi : phi_i) {
                s.phi_i_deg = phi;
                if (simulation_grid(stack, s).is_unfolded()) return true;
            }
            return simulation_grid(stack, s).is_unfolded();
        },
        py::arg("stack"), py::arg("phi_i"));
    m.def("_run_study", &run_study_py, py::arg("configs"), py::arg("settings"),
          py::arg("externals"), py::arg("out"), py::arg("figures"));
    // The configurations a study runs at `preset` (the iridescent, brushed and dispersive
    // categories in the larger ones).
    m.def(
        "_builtin_configurations",
        [](const std::string& preset) {
            py::list out;
            for (const StudyConfiguration& c : preset_configurations(preset)) {
                py::dict d;
                d["id"] = c.id;
                d["category"] = c.category;
                d["stack"] = c.stack;
                out.append(d);
            }
            return out;
        },
        py::arg("preset") = "quick");
    m.def("_filter_configurations", [](py::list configs, const std::string& pattern) {
        // Filters by id with the CLI's --only rule (globs, commas).
        std::vector<StudyConfiguration> cs;
        for (py::handle c : configs) {
            StudyConfiguration sc;
            sc.id = c["id"].cast<std::string>();
            cs.push_back(sc);
        }
        std::vector<std::string> keep;
        for (const StudyConfiguration& c : filter_configurations(cs, pattern))
            keep.push_back(c.id);
        return keep;
    });
}

// lamina.models and lamina.Model: the registry's models, evaluated and sampled.
void bind_models(py::module_& m) {
    m.def(
        "models",
        [] {
            py::list out;
            for (const ModelEntry& e : model_registry()) {
                py::list options;
                for (const OptionSpec& o : e.options()) {
                    py::dict d;
                    d["key"] = o.key;
                    d["values"] = o.values;
                    d["default"] = o.default_value;
                    d["help"] = o.help;
                    options.append(d);
                }
                py::dict d;
                d["name"] = e.name;
                d["description"] = e.description;
                d["supports"] = e.supports;
                d["stochastic"] = e.stochastic;
                d["options"] = options;
                out.append(d);
            }
            return out;
        },
        "Every model of the registry (lamina models): name, description, supports, options");

    py::class_<PyModel>(m, "Model", "An analytic layered model for one stack (docs/models.md)")
        .def(py::init([](const std::string& name, py::handle stack, py::kwargs kwargs) {
                 auto pm = std::make_unique<PyModel>();
                 const ModelEntry& entry = find_model(name, "name");
                 // A keyword cannot hold a dash: the option round-trip is the keyword round_trip.
                 const std::vector<OptionSpec> specs = entry.options();
                 std::vector<std::string> assignments;
                 for (auto [k, v] : kwargs) {
                     const std::string keyword = py::str(k).cast<std::string>();
                     std::string key = keyword;
                     std::replace(key.begin(), key.end(), '_', '-');
                     if (std::none_of(specs.begin(), specs.end(),
                                      [&](const OptionSpec& o) { return o.key == key; })) {
                         std::vector<std::string> keywords;
                         for (const OptionSpec& o : specs) {
                             keywords.push_back(o.key);
                             std::replace(keywords.back().begin(), keywords.back().end(), '-', '_');
                         }
                         throw InputError(
                             "arguments", keyword,
                             fmt::format(
                                 "model '{}' has no option '{}'; its options: {}", name, keyword,
                                 keywords.empty() ? "none"
                                                  : fmt::format("{}", fmt::join(keywords, ", "))));
                     }
                     assignments.push_back(key + "=" + option_text(v));
                 }
                 pm->name = name;
                 pm->stack = stack_of(stack);
                 pm->options = resolve_options(entry, assignments, "options");
                 pm->model = entry.make(pm->stack, pm->options);
                 return pm;
             }),
             py::arg("name"), py::arg("stack"))
        .def_property_readonly("name", [](const PyModel& m) { return m.name; })
        .def_property_readonly("stack", [](const PyModel& m) { return m.stack; })
        .def_property_readonly("options", [](const PyModel& m) { return m.options; })
        .def_property_readonly("support",
                               [](const PyModel& m) { return support_of(m.model->support()); })
        .def_property_readonly("has_sampling",
                               [](const PyModel& m) { return m.model->has_sampling(); })
        .def("eval", &model_eval, py::arg("wi"), py::arg("wo"),
             "f(wi, wo) in 1/sr (no cosine, delta lobes excluded), broadcast over [..., 3] "
             "arrays of unit vectors; [..., 3] RGB. Zero where wi.z <= 0 or on an unsupported side")
        .def("sample", &model_sample, py::arg("wi"), py::arg("u"),
             "Importance sampling: (wo, weight = f|cos θo|/pdf, pdf, valid) for uniforms u "
             "[..., 3] in [0, 1)")
        .def("pdf", &model_pdf, py::arg("wi"), py::arg("wo"), "Density of sample() (1/sr)")
        .def(
            "delta_lobes",
            [](const PyModel& m, std::array<double, 3> wi) {
                py::list out;
                for (const DeltaLobe& d :
                     m.model->delta_lobes(unit_direction(wi[0], wi[1], wi[2], "wi", "")))
                    out.append(py::make_tuple(
                        std::array<double, 3>{d.direction.x, d.direction.y, d.direction.z},
                        std::array<double, 3>{d.energy[0], d.energy[1], d.energy[2]}));
                return out;
            },
            py::arg("wi"), "Delta lobes for one wi: [(direction, energy RGB)]")
        .def(
            "peak_directions",
            [](const PyModel& m, std::array<double, 3> wi) {
                std::vector<std::array<double, 3>> out;
                for (const Vec3d& d :
                     m.model->peak_directions(unit_direction(wi[0], wi[1], wi[2], "wi", "")))
                    out.push_back({d.x, d.y, d.z});
                return out;
            },
            py::arg("wi"))
        .def(
            "binned",
            [](const PyModel& m, py::handle theta_i, std::pair<int, int> grid,
               py::handle phi_i_arg) {
                require_tabulable(find_model(m.name, "name"), "arguments", "name");
                const std::vector<double> thetas = incidences_of(theta_i);
                const double phi_i = degrees_of(phi_i_arg, "phi_i");
                if (!(phi_i >= 0 && phi_i <= 360))  // NaN too
                    throw InputError("arguments", "phi_i",
                                     fmt::format("{} degrees is outside [0, 360]", phi_i));
                SimulationSettings binning;  // the goniophotometer's bins for this stack and φi
                binning.grid = grid_of(grid);
                binning.phi_i_deg = phi_i;
                const HemisphereGrid g = simulation_grid(m.stack, binning);
                const Support s = m.model->support();
                if (!s.brdf && !s.btdf)
                    throw InputError("arguments", "name", "not supported: " + s.reason);
                py::gil_scoped_release release;
                return bin_model(*m.model, g, thetas, phi_i);
            },
            py::arg("theta_i") = default_incidences_deg(),
            py::arg("grid") = std::make_pair(HemisphereGrid{}.n_theta(), HemisphereGrid{}.n_phi()),
            py::arg("phi_i") = 0.0,
            "Cos-weighted bin averages on the goniophotometer's bins (lamina eval --binned): "
            "the unfolded grid (phi over [0, 360)) for an anisotropic stack or phi_i != 0")
        .def(
            "albedo",
            [](const PyModel& m, py::handle theta_i, const std::string& side) {
                // Its adaptive quadrature is the bins' (a noisy estimator would never end it).
                require_tabulable(find_model(m.name, "name"), "arguments", "name");
                const std::vector<double> thetas = incidences_of(theta_i);
                if (side != "R" && side != "T")
                    throw InputError("arguments", "side", "must be 'R' or 'T'");
                // An unsupported side is refused, as binned refuses it (its quadrature of a model
                // that evaluates to 0 there would be a silent 0).
                const Support s = m.model->support();
                if (side == "R" ? !s.brdf : !s.btdf)
                    throw InputError(
                        "arguments", "side",
                        fmt::format(
                            "not supported: {} ({})",
                            s.reason.empty() ? "this model has no such side here" : s.reason,
                            side == "R" ? "BRDF" : "BTDF"));
                // One incidence (a Python or numpy number, a 0-d array): one RGB value.
                const bool scalar = is_one_value(theta_i);
                py::array_t<double> out(std::vector<py::ssize_t>{py::ssize_t(thetas.size()), 3});
                {
                    py::gil_scoped_release release;
                    BinnedOptions options;
                    options.full_azimuth = m.stack.is_anisotropic();
                    for (std::size_t i = 0; i < thetas.size(); ++i) {
                        const Rgbd a = model_albedo(
                            *m.model, incident_direction(deg_to_rad(thetas[i])),
                            side == "R" ? Side::Reflection : Side::Transmission, options);
                        for (int c = 0; c < 3; ++c)
                            out.mutable_data()[3 * i + c] = a[c];
                    }
                }
                if (scalar) return py::array_t<double>(out.attr("reshape")(3));
                return out;
            },
            py::arg("theta_i"), py::arg("side") = "R",
            "Directional albedo ∫ f |cos θo| dωo (RGB) of one side, delta lobes included")
        .def("__repr__", [](const PyModel& m) {
            return fmt::format("<lamina.Model {} on {}>", m.name, m.stack.name);
        });
}

// `python3 -m lamina ARGS`: the command-line interface in this process (cli/run.cpp), argv[0] the
// name --help shows. The GIL is released while it runs; C's stdout is flushed before Python
// writes again.
void bind_cli(py::module_& m) {
    m.def(
        "cli",
        [](const std::vector<std::string>& args) {
            // argv[0] is the program's name, which the parser reads first.
            std::vector<std::string> owned =
                args.empty() ? std::vector<std::string>{"lamina"} : args;
            std::vector<char*> argv;
            for (std::string& a : owned)
                argv.push_back(a.data());
            argv.push_back(nullptr);
            int code;
            {
                py::gil_scoped_release release;
                code = cli::run(int(owned.size()), argv.data());
                std::fflush(stdout);
                std::fflush(stderr);
            }
            return code;
        },
        py::arg("argv"),
        "Runs lamina's command line (argv[0] the program's name) and returns its exit code.");
}

}  // namespace
}  // namespace lamina

// One function per part of the API, in the order the package uses them.
PYBIND11_MODULE(_lamina, m) {
    using namespace lamina;
    m.doc() = "lamina's compiled core (use the lamina package, docs/python.md)";
    // OMP_NUM_THREADS past kMaxThreads crashed OpenMP's runtime: capped, as the CLI does, with a
    // warning.
    if (const int asked = cap_openmp_threads())
        PyErr_WarnEx(
            PyExc_RuntimeWarning,
            fmt::format("lamina: OpenMP asked for {} threads (OMP_NUM_THREADS); running at "
                        "most {}",
                        asked, kMaxThreads)
                .c_str(),
            1);
    bind_errors(m);
    bind_stack(m);
    bind_table(m);
    bind_simulation(m);
    bind_export(m);
    bind_study(m);
    bind_models(m);
    bind_cli(m);
}
