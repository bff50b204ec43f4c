#pragma once
// The production coats' golden data (tests/models/production/data/*.json: numbers from the
// shippers' own code, with their provenance), read by the tests that hold the models to them.

#include "core/rgb.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <stdexcept>
#include <string>

namespace lamina::test {

/// tests/models/production/data/<name>, parsed.
inline nlohmann::json load_golden(const std::string& name) {
    const std::string path =
        std::string(LAMINA_SOURCE_DIR) + "/tests/models/production/data/" + name;
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path);
    return nlohmann::json::parse(in);
}

/// A JSON triple as RGB.
inline Rgbd golden_rgb(const nlohmann::json& j) {
    return Rgbd(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

}  // namespace lamina::test
