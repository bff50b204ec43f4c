#pragma once
// The measured spectra lamina ships (data/, each folder's README.md names the sources), embedded
// in the binary at build time: the metals' n, k (data/nk), the glasses' Sellmeier coefficients
// (data/glass) and the CIE 1931 observer and illuminant D65 (data/cie).

#include <string_view>

namespace lamina {

/// The text of the data file at `path` under data/ (e.g. "nk/Au.csv"); empty if lamina ships none.
std::string_view spectral_data_file(std::string_view path);

}  // namespace lamina
