#include "render/contact_sheet.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/math.h"

#include "models/registry.h"

#include <fmt/format.h>

#include <cstdio>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>

namespace lamina {

namespace {

// A 5×7 bitmap font: each glyph is 7 rows of 5 bits (bit 4 = leftmost column).
const std::map<char, std::array<std::uint8_t, 7>>& font() {
    static const std::map<char, std::array<std::uint8_t, 7>> glyphs = {
        {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
        {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
        {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}},
        {'D', {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}},
        {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}},
        {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
        {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}},
        {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
        {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
        {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
        {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
        {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
        {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
        {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
        {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
        {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
        {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}},
        {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
        {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}},
        {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
        {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
        {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
        {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}},
        {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
        {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}},
        {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
        {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
        {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
        {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
        {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
        {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
        {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
        {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
        {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
        {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
        {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
        {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
        {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
        {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
        {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
        {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
        {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
        {'\'', {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
        {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
        {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
        {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
        {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
        {' ', {0, 0, 0, 0, 0, 0, 0}},
    };
    return glyphs;
}

double luminance(const Rgbf& c) {
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

// Diverging scale: −1 blue, 0 white, +1 red (display-referred linear values).
Rgbf diverging(double t) {
    t = std::clamp(t, -1.0, 1.0);
    if (t < 0) return Rgbf(float(1 + t * 0.85), float(1 + t * 0.6), 1.f);
    return Rgbf(1.f, float(1 - t * 0.75), float(1 - t * 0.85));
}

double display(double linear, double ev) {
    // Tone-map then decode sRGB back to linear so that write_png(tone_map = false) re-encodes it.
    const double x = std::max(0.0, linear) * std::exp2(ev);
    return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

}  // namespace

void draw_text(Image& img, int x, int y, const std::string& text, int s, Rgbf c) {
    int cx = x;
    for (char ch : text) {
        const auto it = font().find(char(std::toupper(static_cast<unsigned char>(ch))));
        if (it != font().end())
            for (int row = 0; row < 7; ++row)
                for (int col = 0; col < 5; ++col)
                    if (it->second[row] & (0x10 >> col))
                        for (int dy = 0; dy < s; ++dy)
                            for (int dx = 0; dx < s; ++dx) {
                                const int X = cx + col * s + dx, Y = y + row * s + dy;
                                if (X >= 0 && Y >= 0 && X < img.width && Y < img.height)
                                    img.at(X, Y) = c;
                            }
        cx += 6 * s;
    }
}

double relative_rmse(const Image& image, const Image& reference, const std::vector<char>& mask) {
    double se = 0, sum = 0;
    long n = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (!mask[i]) continue;
        for (int c = 0; c < 3; ++c) {
            se += sqr(double(image.pixels[i][c]) - reference.pixels[i][c]);
            sum += reference.pixels[i][c];
        }
        n += 3;
    }
    if (n == 0 || sum <= 0) return 0;
    return std::sqrt(se / n) / (sum / n);
}

Image contact_sheet(const std::vector<SheetEntry>& entries, const std::vector<char>& mask,
                    double ev) {
    const Image& ref = entries.at(0).image;
    const int S = ref.width, pad = 12, n = int(entries.size());
    // Font scale: 2 when a tile holds ~20 characters at that size, else 1 (labels never overlap).
    const int fs = S >= 6 * 2 * 20 ? 2 : 1, label = 10 * fs + 8;
    const std::size_t max_chars = std::size_t(std::max(1, (S + pad) / (6 * fs) - 1));
    auto fit = [&](const std::string& t) { return t.substr(0, max_chars); };
    const int W = n * (S + pad) + pad, H = 2 * (S + label + pad) + pad + 10 * fs + 8;
    Image sheet(W, H, Rgbf(0.02f));
    const Rgbf white(0.9f), grey(0.5f);
    double mean_ref = 0;
    long count = 0;
    for (std::size_t i = 0; i < mask.size(); ++i)
        if (mask[i]) {
            mean_ref += luminance(ref.pixels[i]);
            ++count;
        }
    mean_ref = count ? mean_ref / count : 1;
    if (mean_ref <= 0) mean_ref = 1;
    for (int k = 0; k < n; ++k) {
        const SheetEntry& e = entries[k];
        const int x0 = pad + k * (S + pad), y0 = pad + label;
        draw_text(sheet, x0, pad, fit(k == 0 ? e.label + " (REF)" : e.label), fs, white);
        if (!e.supported) {
            draw_text(sheet, x0 + 4, y0 + S / 2 - 10, fit("NOT SUPPORTED"), fs, grey);
            draw_text(sheet, x0 + 4, y0 + S / 2 + 10, e.reason.substr(0, std::size_t(S / 6)), 1,
                      grey);
            continue;
        }
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x) {
                const Rgbf& v = e.image.at(x, y);
                sheet.at(x0 + x, y0 + y) = Rgbf(float(display(v[0], ev)), float(display(v[1], ev)),
                                                float(display(v[2], ev)));
            }
        const int y1 = y0 + S + label + pad;
        if (k == 0) {
            // The colour scale of the difference images.
            const int bw = S - 20, bx = x0 + 10, by = y1 + S / 2 - 10;
            for (int x = 0; x < bw; ++x)
                for (int y = 0; y < 20; ++y)
                    sheet.at(bx + x, by + y) = diverging(2.0 * x / (bw - 1) - 1);
            draw_text(sheet, bx, by + 26, "-50%", fs, white);
            draw_text(sheet, bx + bw / 2 - 3 * fs, by + 26, "0", fs, white);
            draw_text(sheet, bx + bw - 24 * fs, by + 26, "+50%", fs, white);
            draw_text(sheet, bx, by - 20 * fs - 4, fit("(MODEL - REF)"), fs, white);
            draw_text(sheet, bx, by - 10 * fs - 2, fit("/ MEAN REF"), fs, white);
            continue;
        }
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x) {
                const std::size_t i = std::size_t(y) * S + x;
                sheet.at(x0 + x, y1 + y) =
                    mask[i] ? diverging((luminance(e.image.pixels[i]) - luminance(ref.pixels[i])) /
                                        mean_ref / 0.5)
                            : Rgbf(0.1f);
            }
        draw_text(sheet, x0, y1 + S + 6,
                  fit(fmt::format("RMSE {:.3f}", relative_rmse(e.image, ref, mask))), fs, white);
    }
    return sheet;
}

std::string write_comparison(const Stack& stack, const Environment& env,
                             const RenderSettings& settings, const std::filesystem::path& dir,
                             double exposure_ev, const std::vector<std::string>& rw_options) {
    RenderSettings s = settings;
    s.lobe_alpha = lobe_alpha_for(stack);
    s.brushed = brushed_for(stack);
    s.transparent = false;  // the models render the BRDF only: compare like with like
    // Every file is staged and moved into place at the end: an interrupted or failed comparison
    // leaves no half set of images (nor a folder it made), and the images of models that do not
    // support this stack, left by an earlier comparison in the same folder, are removed.
    StagedOutput out(dir, "--out");
    auto write_pair = [&](const std::string& name, const Image& img) {
        write_png(out.stage_path(name + ".png"), img, exposure_ev);
        write_exr(out.stage_path(name + ".exr"), img);
    };
    std::vector<SheetEntry> entries;
    const auto reference = make_model("random-walk", stack, rw_options);
    const Rendering ref = render_sphere(*reference, env, s);
    write_pair("random-walk", ref.image);
    entries.push_back({"random-walk", ref.image, true, ""});
    std::string summary =
        fmt::format("model,rel_rmse,seconds\nrandom-walk,0,{:.2f}\n", ref.seconds);
    for (const ModelEntry& e : model_registry()) {
        if (e.stochastic) continue;
        const auto model = e.make(stack, resolve_options(e, {}));
        if (!model->support().brdf) {
            entries.push_back({e.name, Image(), false, model->support().reason});
            summary += fmt::format("{},not supported,\n", e.name);
            out.remove_unless_staged(e.name + ".png");
            out.remove_unless_staged(e.name + ".exr");
            continue;
        }
        const Rendering r = render_sphere(*model, env, s);
        write_pair(e.name, r.image);
        summary += fmt::format("{},{:.6f},{:.2f}\n", e.name,
                               relative_rmse(r.image, ref.image, ref.mask), r.seconds);
        entries.push_back({e.name, r.image, true, ""});
    }
    write_png(out.stage_path("compare.png"), contact_sheet(entries, ref.mask, exposure_ev), 0,
              false);
    out.add("errors.csv", summary);
    out.commit();
    return summary;
}

}  // namespace lamina
