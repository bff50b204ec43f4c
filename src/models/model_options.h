#pragma once
// A model's options, declared once. Each option names what it sets in the model's choices struct
// (a member, or a few members for an option whose values combine them), the text of every value it
// may take and one line of help. Everything else is derived from that one table: the OptionSpecs
// that `lamina models --options`, the registry's validation and the study's ablations read (the
// default is the value that holds for the variant's default choices), and the parser that turns
// validated options into the struct. A variant of a family is its default choices.

#include "core/check.h"
#include "core/enum_names.h"
#include "models/model.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace lamina {

template <typename Choices>
struct ModelOption {
    struct Value {
        std::string text;
        std::function<void(Choices&)> apply;        ///< sets the choices this value names
        std::function<bool(const Choices&)> holds;  ///< whether `choices` are this value's
    };
    std::string key;
    std::vector<Value> values;  ///< in the order `lamina models --options` lists them
    std::string help;
};

/// An option over one member: each value's text paired with the member's value.
template <typename Choices, typename T>
ModelOption<Choices> member_option(std::string key, T Choices::*member,
                                   std::vector<std::pair<std::string, T>> values,
                                   std::string help) {
    ModelOption<Choices> option{std::move(key), {}, std::move(help)};
    for (auto& [text, value] : values)
        option.values.push_back({std::move(text),
                                 [member, value](Choices& c) { c.*member = value; },
                                 [member, value](const Choices& c) { return c.*member == value; }});
    return option;
}

/// An on/off option over a bool member.
template <typename Choices>
ModelOption<Choices> on_off_member(std::string key, bool Choices::*member, std::string help) {
    return member_option<Choices, bool>(std::move(key), member, {{"on", true}, {"off", false}},
                                        std::move(help));
}

/// An option over a named enum member (core/enum_names.h): its values are the enum's names, in
/// their order.
template <typename Choices, typename E>
ModelOption<Choices> enum_member(std::string key, E Choices::*member, std::string help) {
    std::vector<std::pair<std::string, E>> values;
    for (const auto& n : enum_names(E{}))
        values.emplace_back(n.text, n.value);
    return member_option<Choices, E>(std::move(key), member, std::move(values), std::move(help));
}

template <typename Choices>
class ModelOptionTable {
  public:
    explicit ModelOptionTable(std::vector<ModelOption<Choices>> options)
        : options_(std::move(options)) {}

    /// The specs of a variant whose defaults are `defaults`: each option's default is the first of
    /// its values that holds for them (one must: a table that cannot name a variant's default is
    /// a programming error).
    std::vector<OptionSpec> specs(const Choices& defaults) const {
        std::vector<OptionSpec> out;
        for (const ModelOption<Choices>& o : options_) {
            OptionSpec spec{o.key, {}, {}, o.help};
            for (const auto& v : o.values) {
                spec.values.push_back(v.text);
                if (spec.default_value.empty() && v.holds(defaults)) spec.default_value = v.text;
            }
            LAMINA_CHECK(!spec.default_value.empty());
            out.push_back(std::move(spec));
        }
        return out;
    }

    /// `defaults` with the value of every option in `options` applied (validated and completed by
    /// resolve_options; an option absent from `options` leaves its members as they are).
    Choices parse(const ModelOptions& options, Choices defaults = {}) const {
        for (const ModelOption<Choices>& o : options_) {
            const auto it = options.find(o.key);
            if (it == options.end()) continue;
            for (const auto& v : o.values)
                if (v.text == it->second) v.apply(defaults);
        }
        return defaults;
    }

  private:
    std::vector<ModelOption<Choices>> options_;
};

/// A family of models for the registry (models/registry.cpp): its option table, the default
/// choices of each of its variants (by registry name), and the model built from choices. A
/// variant's options and factory follow from these three (the variant's defaults, then the
/// user's flags).
template <typename Choices>
struct ModelFamily {
    const ModelOptionTable<Choices>& (*table)(const std::string& name);
    Choices (*variant)(const std::string& name);
    std::unique_ptr<Model> (*make)(const std::string& name, const Stack& stack,
                                   const Choices& choices);
};

}  // namespace lamina
