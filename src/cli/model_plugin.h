#pragma once
// `--model-plugin [NAME=]FILE.py` for lamina study and compare: a Python model (docs/python.md)
// joins the study as an external model. The CLI does not embed Python: for each configuration it
// runs the Python module (`python3 -m lamina.plugin_table`, src/python/lamina/plugin_table.py),
// which bins the model with lamina's quadrature and writes its table, read back here. A lamina
// built without the Python module refuses the option with a message saying so.

#include "study/study.h"

#include <string>

namespace lamina::cli {

/// The external model of one `--model-plugin` assignment (InputError naming the option for a
/// missing file or a build without Python). Each configuration's table is binned at its
/// incidences (θi, φi) on its grid, unfolded ones included: the model gets wi and wo in the
/// stack's frame, over the full azimuth there.
ExternalModel model_plugin(const std::string& assignment);

}  // namespace lamina::cli
