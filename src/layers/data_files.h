#pragma once
// The data files lamina ships (data/, each folder's README.md names the sources), embedded in the
// binary at build time: the metals' n, k (data/nk), the glasses' Sellmeier coefficients
// (data/glass), the CIE 1931 observer and illuminant D65 (data/cie), and the lookup tables two
// production coats ship (data/production).

#include <string>
#include <string_view>
#include <vector>

namespace lamina {

/// The text of the data file at `path` under data/ (e.g. "nk/Au.csv"); empty if lamina ships none.
std::string_view data_file(std::string_view path);
/// The cells of each line of the CSV data file at `path`, its header line skipped (empty lines
/// skipped; no rows if lamina ships no such file).
std::vector<std::vector<std::string>> data_file_rows(std::string_view path);

}  // namespace lamina
