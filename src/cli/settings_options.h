#pragma once
// The command line of a settings struct (core/setting.h): one option per setting, --NAME with '-'
// for '_', its help and its default as the setting declares them. CLI11 hands the option's text to
// the setting's codec, which writes the member; a bad value is an InputError naming the option.

#include "core/setting.h"
#include "layers/transport_settings.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

namespace lamina::cli {

/// Adds the option of one setting: --NAME, its help, the codec behind it, its default now.
template <typename T>
void add_setting_option(CLI::App* cmd, const SettingInfo& info, T& member) {
    const std::string flag = option_name(info.name);
    CLI::Option* option = cmd->add_option_function<std::string>(
        flag,
        [&member, info, flag](const std::string& text) {
            member = SettingCodec<T>::from_text(text, info, "command line", flag);
        },
        info.help);
    option->default_str(SettingCodec<T>::to_text(member));
}

/// Adds the options of every setting of `s` but those named in `skip`. `s` must outlive the
/// parse (the options write into it); the defaults shown are its values now.
template <typename S>
void add_settings_options(CLI::App* cmd, S& s, const std::vector<std::string>& skip = {}) {
    S::fields(s, [&](const SettingInfo& info, auto& member) {
        if (std::find(skip.begin(), skip.end(), info.name) == skip.end())
            add_setting_option(cmd, info, member);
    });
}

/// Adds the options of the settings of `s` named in `only` (a command that shares a few of a
/// struct's settings, e.g. eval's spectral range with simulate's).
template <typename S>
void add_settings_options_only(CLI::App* cmd, S& s, const std::vector<std::string>& only) {
    S::fields(s, [&](const SettingInfo& info, auto& member) {
        if (std::find(only.begin(), only.end(), info.name) != only.end())
            add_setting_option(cmd, info, member);
    });
}

/// `--physics exact|bpb19` (layers/transport_settings.h): sets the transport settings it names.
/// Add it before the transport's own options: CLI11 runs the callbacks in the order the options
/// were added, so an explicit `--microsurface` or `--polarization` given beside it wins.
inline void add_physics_option(CLI::App* cmd, TransportSettings& transport) {
    const SettingInfo info{.name = "physics",
                           .help =
                               "The reference: exact (polarization on, microsurface multiple: "
                               "the defaults) or bpb19 (the 2019 study's: polarization off, "
                               "microsurface single); --polarization, --microsurface override"};
    cmd->add_option_function<std::string>(
        "--physics",
        [&transport, info](const std::string& text) {
            apply_physics(
                SettingCodec<ReferencePhysics>::from_text(text, info, "command line", "--physics"),
                transport);
        },
        info.help);
}

}  // namespace lamina::cli
