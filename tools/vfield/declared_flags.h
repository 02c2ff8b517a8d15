#pragma once
// Command-line flags derived from an options struct's declaration of its
// fields (vfield/core/fields.h): one --kebab-case flag per number, name or
// switch, its help from the field's doc and default. What a flag is given is
// kept as the JSON the scene file would hold, so that it is read and checked
// by the same declaration as a scene's keys.

#include "command.h"

#include <vfield/core/field_visitors.h>

#include <cctype>
#include <string>
#include <utility>
#include <vector>

namespace vfield::cli {

/// "maxPerLeaf" -> "--max-per-leaf".
std::string flagName(const std::string& key);

/// The values given to declared flags, in the order given.
class DeclaredFlags {
public:
    /// Adds a flag for each number, name or switch that Options declares
    /// (sections and alternatives have none).
    template<typename Options>
    void addTo(CLI::App& command)
    {
        const Options defaults{};
        Adder adder{command, *this};
        Options::visitFields(defaults, adder);
    }

    /// key -> JSON text ("12", "\"doubling\"", "true").
    const std::vector<std::pair<std::string, std::string>>& values() const { return mValues; }
    /// The values as a JSON object's text, after the keys of `base` (an object).
    std::string jsonObject(const nlohmann::json& base = nlohmann::json::object()) const;

    /// Options read from base's keys and the flags given, over their
    /// defaults, checked by their declaration; a bad value is a ValueError
    /// naming its flag.
    template<typename Options>
    Options read(const nlohmann::json& base = nlohmann::json::object()) const
    {
        try {
            return readValidated<Options>(parseJson(jsonObject(base), "command line"));
        } catch (const ParseError& e) {
            throw ValueError(flagOf(e));
        }
    }

private:
    /// "--max-level: expected ..." from an error at "/maxLevel".
    std::string flagOf(const ParseError& error) const;

    struct Adder {
        CLI::App& command;
        DeclaredFlags& flags;

        template<typename T>
        void operator()(const Field<T>& f)
        {
            using V = std::remove_const_t<T>;
            if constexpr (detail::IsOptional<V>::value) add<typename V::value_type>(f, f.defaultOverride());
            else if constexpr (!detail::IsProxy<V>::value) add<V>(f, nullptr);
        }
        template<typename S>
        void operator()(const InlineFields<S>& section)
        {
            S::visitFields(*section.value, *this);
        }
        template<typename Declare>
        void operator()(const Group<Declare>&)
        {}

        template<typename V, typename T>
        void add(const Field<T>& f, const char* defaultText)
        {
            if (f.selector()) return;
            const std::string key = f.key(), name = flagName(key);
            std::string help = f.docText();
            if (!help.empty()) help[0] = char(std::toupper(static_cast<unsigned char>(help[0])));
            auto& values = flags.mValues;
            if constexpr (std::is_same_v<V, bool>) {
                command.add_flag_callback(
                    name,
                    [&values, key] {
                        values.push_back({key, "true"});
                    },
                    help);
            } else if constexpr (std::is_enum_v<V> || std::is_same_v<V, std::string>) {
                if constexpr (std::is_enum_v<V>) help += std::string(" [default: ") + enumName(*f.ref()) + "]";
                CLI::Option* option = command.add_option_function<std::string>(
                    name,
                    [&values, key](const std::string& text) {
                        values.push_back({key, nlohmann::json(text).dump()});
                    },
                    help);
                if constexpr (std::is_enum_v<V>) {
                    std::string names;
                    for (const std::string& n : enumNameList<V>()) names += (names.empty() ? "" : "|") + n;
                    option->check(CLI::IsMember(enumNameList<V>()).description(""))->type_name(names);
                }
            } else if constexpr (std::is_arithmetic_v<V>) {
                help += " [default: " + (defaultText ? std::string(defaultText) : defaultOf(f)) + "]";
                command
                    .add_option_function<std::string>(
                        name,
                        [&values, key, name](const std::string& text) {
                            const nlohmann::json number = nlohmann::json::parse(text, nullptr, false);
                            if (!number.is_number()) throw CLI::ValidationError(name, "expected a number, got '" + text + "'");
                            values.push_back({key, text});
                        },
                        help)
                    ->type_name(detail::kIsInteger<V> ? "N" : "NUMBER");
            }
        }
        template<typename T>
        static std::string defaultOf(const Field<T>& f)
        {
            if constexpr (detail::IsOptional<std::remove_const_t<T>>::value) return "none";
            else return detail::numberDocText(double(*f.ref()));
        }
    };

    std::vector<std::pair<std::string, std::string>> mValues;
};

} // namespace vfield::cli
