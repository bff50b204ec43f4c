#include "export/npz.h"

#include "core/check.h"
#include "export/bytes.h"

#include <zlib.h>

#include <cstdint>
#include <cstring>

namespace lamina {

// The layout of PKWARE's APPNOTE (sections 4.3.7, 4.3.12, 4.3.16): per member a local header and
// the data, then the central directory and its end record. No ZIP64: members under 4 GiB.
std::string zip_stored(const std::vector<std::pair<std::string, std::string>>& members) {
    std::string out, central;
    for (const auto& [name, data] : members) {
        LAMINA_CHECK(data.size() < 0xffffffffu && out.size() < 0xffffffffu);
        const std::uint32_t crc = std::uint32_t(
            crc32(0L, reinterpret_cast<const Bytef*>(data.data()), uInt(data.size())));
        const std::uint32_t offset = std::uint32_t(out.size());
        auto common = [&](std::string& s) {
            append_bytes<std::uint16_t>(s, 20);    // version needed: 2.0
            append_bytes<std::uint16_t>(s, 0);     // flags
            append_bytes<std::uint16_t>(s, 0);     // method: stored
            append_bytes<std::uint16_t>(s, 0);     // time
            append_bytes<std::uint16_t>(s, 0x21);  // date: 1980-01-01
            append_bytes<std::uint32_t>(s, crc);
            append_bytes<std::uint32_t>(s, std::uint32_t(data.size()));
            append_bytes<std::uint32_t>(s, std::uint32_t(data.size()));
            append_bytes<std::uint16_t>(s, std::uint16_t(name.size()));
            append_bytes<std::uint16_t>(s, 0);  // extra length
        };
        append_bytes<std::uint32_t>(out, 0x04034b50);
        common(out);
        out += name;
        out += data;
        append_bytes<std::uint32_t>(central, 0x02014b50);
        append_bytes<std::uint16_t>(central, 20);  // version made by
        common(central);
        append_bytes<std::uint16_t>(central, 0);  // comment length
        append_bytes<std::uint16_t>(central, 0);  // disk
        append_bytes<std::uint16_t>(central, 0);  // internal attributes
        append_bytes<std::uint32_t>(central, 0);  // external attributes
        append_bytes<std::uint32_t>(central, offset);
        central += name;
    }
    const std::uint32_t central_offset = std::uint32_t(out.size());
    out += central;
    append_bytes<std::uint32_t>(out, 0x06054b50);
    append_bytes<std::uint16_t>(out, 0);
    append_bytes<std::uint16_t>(out, 0);
    append_bytes<std::uint16_t>(out, std::uint16_t(members.size()));
    append_bytes<std::uint16_t>(out, std::uint16_t(members.size()));
    append_bytes<std::uint32_t>(out, std::uint32_t(central.size()));
    append_bytes<std::uint32_t>(out, central_offset);
    append_bytes<std::uint16_t>(out, 0);
    return out;
}

}  // namespace lamina
