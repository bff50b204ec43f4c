#pragma once
// The explorer page of a study directory (docs/explorer.md): DIR/index.html and DIR/explorer/,
// one page that works from file:// with no network and no server. It reads what `lamina study`
// wrote (docs/formats.md: study.json, metrics.csv, configs/<id>/{config.json, tables.lza,
// reference_se.lza}) and nothing else, so it can be regenerated at any time.

#include <cstdint>
#include <filesystem>

namespace lamina {

struct ExplorerSummary {
    std::size_t configurations = 0;
    std::uintmax_t data_bytes = 0;  ///< DIR/explorer/data/*.js, all together
    std::size_t unchanged = 0;      ///< configurations whose data was not encoded again
};

/// Writes DIR/index.html, DIR/explorer/{plotly.min.js, explorer.js, explorer.css} and
/// DIR/explorer/data/{index.js, <id>.js}. Throws InputError naming the file for a missing or
/// malformed study file (study.json first) or a folder that cannot be written; files are staged and
/// moved into place only when every one is written. A file whose content is unchanged is not
/// rewritten, and a configuration whose inputs are those of the last page is not encoded again
/// (DIR/explorer/data/.inputs.json holds their digests).
ExplorerSummary write_explorer(const std::filesystem::path& study_dir);

}  // namespace lamina
