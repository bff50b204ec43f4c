#pragma once
// The comparison sheet of `lamina render --compare`: the reference rendering and every model's,
// side by side, each with a difference image below it, a colour scale and an error number.
//
// Difference: d = (L_model − L_ref) / mean_sphere(L_ref) on luminance (Rec. 709 weights), shown
// with a diverging blue–white–red scale over [−0.5, 0.5] (clamped). Error number: relative RMSE
// over the pixels fully on the sphere, √(mean (L_model − L_ref)²) / mean(L_ref), per RGB
// channel pooled. Labels are drawn with a built-in 5×7 bitmap font (upper case, digits, . - + % :
// =).

#include "layers/stack.h"
#include "render/environment.h"
#include "render/image.h"
#include "render/renderer.h"

#include <filesystem>

#include <string>
#include <vector>

namespace lamina {

struct SheetEntry {
    std::string label;
    Image image;  ///< linear
    bool supported = true;
    std::string reason;  ///< why not (drawn instead of the image)
};

/// Relative RMSE of `image` against `reference` over `mask` (see above).
double relative_rmse(const Image& image, const Image& reference, const std::vector<char>& mask);

/// Builds the sheet (display-referred, values in [0, 1], to be written with tone_map = false).
/// entries[0] is the reference.
Image contact_sheet(const std::vector<SheetEntry>& entries, const std::vector<char>& mask,
                    double exposure_ev);

/// Renders the random-walk reference and every analytic model of the registry for `stack` with
/// the same settings (the proposal lobe of the light-sampling mixture from the stack,
/// lobe_alpha_for) and writes, into `dir`: one PNG + EXR per model, errors.csv
/// (model,rel_rmse,seconds; "not supported" rows) and compare.png, all staged and moved into place
/// at the end (StagedOutput); the images an earlier comparison left there of models that do not
/// support this stack are removed. Returns the errors.csv text.
std::string write_comparison(const Stack& stack, const Environment& env,
                             const RenderSettings& settings, const std::filesystem::path& dir,
                             double exposure_ev, const std::vector<std::string>& rw_options = {});

/// Draws `text` at (x, y) (top-left), scale s pixels per font pixel, colour c.
void draw_text(Image& img, int x, int y, const std::string& text, int s, Rgbf c);

}  // namespace lamina
