#pragma once
// NumPy .npz archives (numpy.savez's format: a ZIP of .npy members, stored uncompressed here),
// with the export's metadata as a JSON member: `np.load(f)["f"]`, `json.loads(np.load(f)
// ["metadata.json"])` (numpy hands back a member that is not .npy as its bytes).

#include <string>
#include <utility>
#include <vector>

namespace lamina {

/// A ZIP archive (stored, CRC-32 from zlib) of the members, in order: (name, bytes).
std::string zip_stored(const std::vector<std::pair<std::string, std::string>>& members);

}  // namespace lamina
