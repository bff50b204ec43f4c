#pragma once
// The tables lamina-1 reads (lamina1/table_lookups.h has their formats), held together: either
// views of arrays that live elsewhere (lamina hands its own cached tables this way) or arrays
// read from lamina-1's data file. The data file is what a renderer ships beside this header;
// `lamina export --lamina1-tables FILE` writes it.
//
// The data file, little-endian: the 16 bytes "lamina1-tables\n\0", a uint32 format version (1),
// a uint32 section count, then per section a 24-byte NUL-padded name, a uint32 element type
// (0 float32, 1 float64, 2 uint32, 3 bytes), a uint64 element count and the elements. Sections:
// "axes" (the axes' description as text, axes_text: it must equal this header's),
// "transmittance-smith", "transmittance-walter" (optional), "fgd-offset", "fgd-w", "fgd-x" (the FGD
// table as its bins, FgdBins: its nodes are rebuilt for each material from them, FgdView),
// "slope-sum", "multiple-scattering".

#include "lamina1/math.h"
#include "lamina1/physics.h"
#include "lamina1/table_lookups.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace lamina1 {

class Tables {
  public:
    Tables() = default;
    Tables(const Tables&) = delete;
    Tables& operator=(const Tables&) = delete;
    Tables(Tables&&) = default;
    Tables& operator=(Tables&&) = default;

    /// The arrays, or null where absent (a masking the file does not hold; the multiple-
    /// scattering table where lamina has not computed it).
    const float* transmittance(Masking masking) const { return transmittance_[int(masking)]; }
    const float* slope_sum() const { return slope_sum_; }
    const float* multiple_scattering() const { return multiple_scattering_; }
    /// The FGD node (ic, ia, ie, ik) (FgdFormat's layout): read from the full table where one is
    /// set, else rebuilt from the bins.
    float fgd_node(int ic, int ia, int ie, int ik) const {
        if (fgd_nodes_) return fgd_nodes_[FgdFormat::index(ic, ia, ie, ik)];
        const std::size_t cell = std::size_t(ic) * FgdFormat::kNalpha + ia;
        const std::uint32_t begin = fgd_bins_.offset[cell], end = fgd_bins_.offset[cell + 1];
        return FgdFormat::node(&fgd_bins_.w[begin], &fgd_bins_.x[begin], int(end - begin), ic, ia,
                               FgdFormat::eta_node(ie), FgdFormat::k_node(ik));
    }
    bool has_full_fgd() const { return fgd_nodes_ != nullptr; }
    /// True when everything a material with this masking (and, with `multiple`, the orders ≥ 2
    /// of its rough interfaces) needs is present.
    bool complete(Masking masking, bool multiple) const {
        return transmittance(masking) && (!multiple || transmittance(Masking::Smith)) &&
               slope_sum_ && (fgd_nodes_ || !fgd_bins_.offset.empty()) &&
               (!multiple || multiple_scattering_);
    }

    /// Views of arrays that outlive this object (lamina's own tables).
    void set_transmittance(Masking masking, const float* values) {
        transmittance_[int(masking)] = values;
    }
    void set_fgd_nodes(const float* values) { fgd_nodes_ = values; }
    void set_fgd_bins(FgdBins bins) { fgd_bins_ = std::move(bins); }
    void set_slope_sum(const float* values) { slope_sum_ = values; }
    void set_multiple_scattering(const float* values) { multiple_scattering_ = values; }

    /// The axes this header's formats have, as the data file records them.
    static std::string axes_text() {
        std::ostringstream s;
        s << "transmittance c" << TransmittanceFormat::kNbelow << '+' << TransmittanceFormat::kNc
          << " a" << TransmittanceFormat::kNalpha << " e" << TransmittanceFormat::kNeta << ':'
          << TransmittanceFormat::kLog2EtaMin << ':' << TransmittanceFormat::kLog2EtaMax
          << "; fgd c" << FgdFormat::kNc << " a" << FgdFormat::kNalpha << " e" << FgdFormat::kNeta
          << ':' << FgdFormat::kLog2EtaMin << ':' << FgdFormat::kLog2EtaMax << " k"
          << FgdFormat::kNk << ':' << FgdFormat::kKMax << "; slope-sum x" << SlopeSumFormat::kNx
          << " y" << SlopeSumFormat::kNy << " u" << SlopeSumFormat::kNu << "; ms m"
          << MultipleScatteringFormat::kNmu << " a" << MultipleScatteringFormat::kNalpha << " e"
          << MultipleScatteringFormat::kNeta;
        return s.str();
    }

    /// The data file's bytes: the arrays present (the FGD as bins, which must be set).
    std::string serialize() const {
        std::string out(kMagic, 16);
        std::vector<Section> sections;
        const std::string axes = axes_text();
        sections.push_back({"axes", 3, axes.size(), axes.data(), 1});
        auto floats = [&](const char* name, const float* v, std::size_t n) {
            if (v) sections.push_back({name, 0, n, v, sizeof(float)});
        };
        floats("transmittance-smith", transmittance_[0], TransmittanceFormat::size());
        floats("transmittance-walter", transmittance_[1], TransmittanceFormat::size());
        sections.push_back({"fgd-offset", 2, fgd_bins_.offset.size(), fgd_bins_.offset.data(),
                            sizeof(std::uint32_t)});
        sections.push_back({"fgd-w", 1, fgd_bins_.w.size(), fgd_bins_.w.data(), sizeof(double)});
        sections.push_back({"fgd-x", 1, fgd_bins_.x.size(), fgd_bins_.x.data(), sizeof(double)});
        floats("slope-sum", slope_sum_, SlopeSumFormat::size());
        floats("multiple-scattering", multiple_scattering_, MultipleScatteringFormat::size());
        put(out, std::uint32_t(kVersion));
        put(out, std::uint32_t(sections.size()));
        for (const Section& s : sections) {
            char name[24] = {};
            std::strncpy(name, s.name, sizeof(name) - 1);
            out.append(name, sizeof(name));
            put(out, std::uint32_t(s.type));
            put(out, std::uint64_t(s.count));
            out.append(static_cast<const char*>(s.data), s.count * s.element_size);
        }
        return out;
    }

    /// Reads a data file's bytes; false (and why, in *error) if they are not one this header reads.
    bool deserialize(const std::string& bytes, std::string* error = nullptr) {
        auto fail = [&](const std::string& why) {
            if (error) *error = why;
            return false;
        };
        if (bytes.size() < 24 || bytes.compare(0, 16, std::string(kMagic, 16)) != 0)
            return fail("not a lamina-1 tables file");
        if (!little_endian()) return fail("this reader needs a little-endian machine");
        std::size_t at = 16;
        std::uint32_t version = 0, count = 0;
        get(bytes, at, version);
        get(bytes, at, count);
        if (version != kVersion) return fail("format version " + std::to_string(version));
        std::string axes;
        for (std::uint32_t i = 0; i < count; ++i) {
            if (bytes.size() < at + 36) return fail("truncated");
            const std::string name(bytes.c_str() + at);
            at += 24;
            std::uint32_t type = 0;
            std::uint64_t n = 0;
            get(bytes, at, type);
            get(bytes, at, n);
            const std::size_t size = type == 1 ? 8 : type == 3 ? 1 : 4;
            if (type > 3 || n > (bytes.size() - at) / size) return fail("truncated: " + name);
            const char* data = bytes.data() + at;
            at += n * size;
            // Each known section has one element type (the reads below copy n elements of it);
            // a section this reader does not know is skipped.
            const bool known = name == "axes" || name == "fgd-offset" || name == "fgd-w" ||
                               name == "fgd-x" || name == "slope-sum" ||
                               name == "multiple-scattering" || name == "transmittance-smith" ||
                               name == "transmittance-walter";
            const std::uint32_t expected = name == "axes"                       ? 3
                                           : name == "fgd-offset"               ? 2
                                           : name == "fgd-w" || name == "fgd-x" ? 1
                                                                                : 0;
            if (known && type != expected) return fail("element type of " + name);
            if (name == "axes") {
                axes.assign(data, n);
            } else if (name == "transmittance-smith" || name == "transmittance-walter") {
                if (n != TransmittanceFormat::size()) return fail("size of " + name);
                const int m = name == "transmittance-smith" ? 0 : 1;
                owned_[m].assign(reinterpret_cast<const float*>(data),
                                 reinterpret_cast<const float*>(data) + n);
                transmittance_[m] = owned_[m].data();
            } else if (name == "slope-sum") {
                if (n != SlopeSumFormat::size()) return fail("size of " + name);
                read_floats(data, n, owned_[2], slope_sum_);
            } else if (name == "multiple-scattering") {
                if (n != MultipleScatteringFormat::size()) return fail("size of " + name);
                read_floats(data, n, owned_[3], multiple_scattering_);
            } else if (name == "fgd-offset") {
                fgd_bins_.offset.resize(n);
                std::memcpy(fgd_bins_.offset.data(), data, n * 4);
            } else if (name == "fgd-w" || name == "fgd-x") {
                std::vector<double>& v = name == "fgd-w" ? fgd_bins_.w : fgd_bins_.x;
                v.resize(n);
                std::memcpy(v.data(), data, n * 8);
            }
        }
        if (axes != axes_text()) return fail("tables of other axes: " + axes);
        const std::size_t cells = std::size_t(FgdFormat::kNc) * FgdFormat::kNalpha;
        if (fgd_bins_.offset.size() != cells + 1 || fgd_bins_.w.size() != fgd_bins_.x.size() ||
            fgd_bins_.offset.back() != fgd_bins_.w.size())
            return fail("the FGD bins are inconsistent");
        for (std::size_t i = 0; i < cells; ++i)
            if (fgd_bins_.offset[i] > fgd_bins_.offset[i + 1])
                return fail("the FGD bins are inconsistent");
        return true;
    }

    /// Reads the data file at `path`; false (and why, in *error) on failure.
    bool read(const std::string& path, std::string* error = nullptr) {
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            if (error) *error = "cannot open " + path;
            return false;
        }
        std::ostringstream bytes;
        bytes << in.rdbuf();
        std::string why;
        if (deserialize(bytes.str(), &why)) return true;
        if (error) *error = path + ": " + why;
        return false;
    }

  private:
    static constexpr const char* kMagic = "lamina1-tables\n\0";
    static constexpr std::uint32_t kVersion = 1;
    struct Section {
        const char* name;
        int type;
        std::size_t count;
        const void* data;
        std::size_t element_size;
    };
    static bool little_endian() {
        const std::uint32_t one = 1;
        unsigned char first;
        std::memcpy(&first, &one, 1);
        return first == 1;
    }
    template <typename T>
    static void put(std::string& out, T v) {
        out.append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    template <typename T>
    static void get(const std::string& in, std::size_t& at, T& v) {
        std::memcpy(&v, in.data() + at, sizeof(T));
        at += sizeof(T);
    }
    static void read_floats(const char* data, std::size_t n, std::vector<float>& owned,
                            const float*& view) {
        owned.resize(n);
        std::memcpy(owned.data(), data, n * sizeof(float));
        view = owned.data();
    }

    const float* transmittance_[2] = {nullptr, nullptr};
    const float* fgd_nodes_ = nullptr;
    const float* slope_sum_ = nullptr;
    const float* multiple_scattering_ = nullptr;
    FgdBins fgd_bins_;
    std::vector<float> owned_[4];
};

/// The FGD nodes that the lookups of one interface read (a fixed roughness and index per
/// channel), gathered once per material: the lookups are then FgdFormat's interpolation itself,
/// on these nodes instead of the whole table. One channel (a dielectric) or three (a conductor).
class FgdView {
  public:
    FgdView() = default;
    FgdView(const Tables& tables, double alpha, double eta, double k)
        : FgdView(tables, alpha, Rgb(eta), Rgb(k), 1) {}
    FgdView(const Tables& tables, double alpha, const Rgb& eta, const Rgb& k)
        : FgdView(tables, alpha, eta, k, 3) {}

    /// FGD(c, α, η, κ) of the first channel.
    double operator()(double c) const {
        return FgdFormat::interpolate([&](int ic, int ia) { return block(ic, ia, 0); }, 2, c,
                                      alpha_, at_[0]);
    }
    /// The three channels (a conductor).
    Rgb rgb(double c) const {
        return FgdFormat::interpolate_rgb([&](int ic, int ia, int i) { return block(ic, ia, i); },
                                          2, c, alpha_, at_);
    }

  private:
    FgdView(const Tables& tables, double alpha, const Rgb& eta, const Rgb& k, int channels)
        : alpha_(alpha), channels_(channels) {
        for (int i = 0; i < 3; ++i)
            at_[i] = FgdFormat::locate(eta[i], k[i]);
        if (!(alpha > 0)) return;  // the exact Fresnel factor: no nodes read
        const double fa = std::sqrt(table_axis(alpha, 0.0, 1.0)) * (FgdFormat::kNalpha - 1);
        ia_ = std::min(int(fa), FgdFormat::kNalpha - 2);
        const bool second_alpha = fa - ia_ > 0;
        nodes_.assign(std::size_t(FgdFormat::kNc) * 2 * channels * 4, 0.0f);
        for (int i = 0; i < channels; ++i) {
            const FgdFormat::Index& at = at_[i];
            // A corner of weight 0 (the index on a node) is read but does not count: where the
            // nodes are rebuilt from bins it is left at 0 (its product with the weight is the
            // same 0), saving its sum.
            const bool full = tables.has_full_fgd();
            const bool corner[4] = {true, full || at.tk > 0, full || at.te > 0,
                                    full || (at.tk > 0 && at.te > 0)};
            int same = -1;
            for (int j = 0; j < i && same < 0; ++j)
                if (at_[j].eta == at.eta && at_[j].k == at.k) same = j;
            for (int ic = 0; ic < FgdFormat::kNc; ++ic)
                for (int da = 0; da < 2; ++da) {
                    float* out = &nodes_[((std::size_t(ic) * 2 + da) * channels + i) * 4];
                    if (same >= 0) {
                        std::memcpy(out,
                                    &nodes_[((std::size_t(ic) * 2 + da) * channels + same) * 4],
                                    4 * sizeof(float));
                        continue;
                    }
                    if (da == 1 && !second_alpha && !full) continue;
                    for (int q = 0; q < 4; ++q)
                        if (corner[q])
                            out[q] = tables.fgd_node(ic, ia_ + da, at.ie + q / 2, at.ik + q % 2);
                }
        }
    }
    const float* block(int ic, int ia, int channel) const {
        return &nodes_[((std::size_t(ic) * 2 + (ia - ia_)) * channels_ + channel) * 4];
    }

    double alpha_ = 0;
    int ia_ = 0, channels_ = 1;
    FgdFormat::Index at_[3];
    std::vector<float> nodes_;
};

}  // namespace lamina1
