#include "study/distributed_reference.h"

#include "core/error.h"
#include "core/progress.h"
#include "study/study.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cstring>

namespace lamina {

namespace {

// The work list travels as JSON; each key is rebuilt from it and checked against the root's
// canonical text, so that every rank simulates exactly the piece the root will store.
nlohmann::json key_json(const ReferenceKey& key) {
    return {{"config_id", key.config_id},
            {"stack", stack_to_json(key.stack)},
            {"settings", settings_to_json(key.settings)},
            {"stokes_tallies", key.settings.stokes_tallies},  // not a setting: said here
            {"canonical", key.canonical()}};
}

ReferenceKey key_from_json(const nlohmann::json& j) {
    ReferenceKey key{j.at("config_id").get<std::string>(),
                     stack_from_json(j.at("stack"), "reference work list"),
                     {}};
    settings_from_json(key.settings, j.at("settings"), "reference work list");
    key.settings.stokes_tallies = j.value("stokes_tallies", false);
    if (key.canonical() != j.at("canonical").get<std::string>())
        throw InputError("reference work list", key.config_id,
                         "this process describes the piece differently from the root: are all "
                         "processes running the same lamina build, with the same SIMD "
                         "instruction set (LAMINA_SIMD_TARGET, docs/scaling.md)?");
    return key;
}

// A posted piece: its index in the work list (8 bytes), then the cache file's bytes.
std::string with_index(std::uint64_t index, const std::string& bytes) {
    std::string out(sizeof(index), '\0');
    std::memcpy(out.data(), &index, sizeof(index));
    return out + bytes;
}

std::uint64_t particles_of(const std::vector<ReferenceKey>& work, int rank, int size) {
    std::uint64_t n = 0;
    for (std::size_t i = std::size_t(rank); i < work.size(); i += std::size_t(size))
        n += work[i].settings.particles;
    return n;
}

}  // namespace

std::vector<ReferenceKey> study_reference_keys(const std::vector<StudyConfiguration>& configs,
                                               const StudySettings& s) {
    std::vector<ReferenceKey> keys;
    for (const StudyConfiguration& config : configs)
        for (const StudyIncidence& inc : study_incidences(config.stack, s.reference))
            keys.push_back(study_reference_key(config, inc, s));
    return keys;
}

std::size_t share_reference_pieces(Communicator& comm, const std::filesystem::path& cache_dir,
                                   const std::vector<ReferenceKey>& keys, int threads) {
    if (!comm.distributed()) return 0;
    // 1. The root lists the pieces its cache lacks; every rank learns the list.
    std::string list_text;
    if (comm.is_root()) {
        nlohmann::json list = nlohmann::json::array();
        for (const ReferenceKey& key : keys)
            if (!load_reference_piece(cache_dir, key)) list.push_back(key_json(key));
        list_text = list.dump();
    }
    comm.broadcast(list_text);
    std::vector<ReferenceKey> work;
    for (const nlohmann::json& j : nlohmann::json::parse(list_text))
        work.push_back(key_from_json(j));

    // 2. Piece i is simulated by rank i mod K.
    const std::size_t size = std::size_t(comm.size()), rank = std::size_t(comm.rank());
    std::unique_ptr<Progress> progress;
    if (comm.is_root())
        progress =
            std::make_unique<Progress>(fmt::format("reference ({} processes)", comm.size()),
                                       "particles", particles_of(work, comm.rank(), comm.size()));
    const auto on_progress = [&](std::uint64_t n) {
        if (progress) progress->advance(n);
    };
    std::size_t received = 0;
    const auto store = [&](const RankMessage& m) {
        std::uint64_t index = 0;
        if (m.bytes.size() < sizeof(index)) comm.abort("a reference piece arrived truncated");
        std::memcpy(&index, m.bytes.data(), sizeof(index));
        if (index >= work.size() || index % size != std::size_t(m.source))
            comm.abort(fmt::format("rank {} sent piece {}, which is not its own", m.source, index));
        store_reference_piece(cache_dir, work[index], m.bytes.substr(sizeof(index)));
        ++received;
    };
    for (std::size_t i = rank; i < work.size(); i += size) {
        std::string bytes = compute_reference_piece(work[i], threads, on_progress);
        if (comm.is_root()) {
            store_reference_piece(cache_dir, work[i], bytes);
            // Store what the others have sent meanwhile (a killed run keeps more of its work).
            while (const std::optional<RankMessage> m = comm.receive_at_root(false))
                store(*m);
        } else {
            comm.post_to_root(with_index(i, bytes));
        }
    }
    // 3. The root waits for the rest; the others for the root to have received everything.
    std::size_t computed = 0;
    for (std::size_t i = rank; i < work.size(); i += size)
        ++computed;
    if (comm.is_root()) {
        while (received < work.size() - computed)
            store(*comm.receive_at_root(true));
        progress->finish();
    } else {
        comm.flush_posts();
    }
    // 4. Every piece once: the ranks' counts add up to the list (a check, cheap).
    std::size_t total = 0;
    for (const std::string& count : comm.gather(std::to_string(computed)))
        total += std::stoull(count);
    if (comm.is_root() && total != work.size())
        comm.abort(fmt::format("internal error: {} reference pieces computed for {} listed", total,
                               work.size()));
    return comm.is_root() ? work.size() : 0;
}

}  // namespace lamina
