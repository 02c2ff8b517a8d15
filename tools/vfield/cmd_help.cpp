// vfield help: reference documentation derived from the code. `keys`: every
// scene key, from the options' declarations; `commands`: every subcommand's
// help text, from the parser's own definitions. --update and --check keep
// documents' tables (docs/scenes.md, docs/command.md) equal to them.

#include "command.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/scene/scene_keys.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace vfield::cli {

namespace {

std::string joined(const std::vector<std::string>& titles)
{
    std::string text;
    for (const std::string& t : titles) text += (text.empty() ? "" : ", ") + t;
    return text;
}

/// The Markdown reference of every subcommand, in the order they were
/// registered: each one's help as `vfield NAME --help` prints it, then its
/// own subcommands'.
std::string commandReference(const CLI::App& app)
{
    std::string text;
    const auto add = [&text](const CLI::App& command, const std::string& parents) {
        const std::string name = parents + " " + command.get_name();
        text += "### `" + name + "`\n\n```text\n" +
                command.get_formatter()->make_help(&command, name, CLI::AppFormatMode::Normal) + "```\n\n";
    };
    for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
        add(*command, "vfield");
        for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; }))
            add(*sub, "vfield " + command->get_name());
    }
    return text;
}

constexpr const char* kCommandsBegin = "<!-- commands -->\n";
constexpr const char* kCommandsEnd = "<!-- end commands -->";

/// The document with the text between its commands markers replaced by reference.
std::string withCommandReference(const std::string& document, const std::string& reference, const std::string& path)
{
    const std::size_t begin = document.find(kCommandsBegin), end = document.rfind(kCommandsEnd);
    if (begin == std::string::npos || end == std::string::npos || end < begin)
        throw FileError(path, "has no lines <!-- commands --> and <!-- end commands --> to hold the reference");
    const std::size_t from = begin + std::string(kCommandsBegin).size();
    return document.substr(0, from) + "\n" + reference + document.substr(end);
}

} // namespace

Runner registerHelp(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        std::vector<std::string> documents;
        std::string commandsDocument;
        bool check = false, update = false, complete = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* help = app.add_subcommand("help", "Reference documentation derived from the code");
    help->require_subcommand(1);
    CLI::App* keys = help->add_subcommand(
        "keys",
        "Every key of a scene file as Markdown tables (type, default, meaning), or the tables of documents checked or updated");
    keys->add_option("documents", o->documents, "Markdown files whose <!-- keys: TITLE --> tables to check or update");
    keys->add_flag("--check", o->check, "Exit 1, naming them, when a document's tables differ from the code's");
    keys->add_flag("--update", o->update, "Rewrite a document's tables from the code");
    keys->add_flag("--complete", o->complete, "With --check: every table must be in the documents");

    CLI::App* commands = help->add_subcommand(
        "commands", "Every subcommand's help as Markdown, or a document's reference of them checked or updated");
    commands->add_option("document", o->commandsDocument,
                         "Markdown file whose command reference, between its commands markers, to check or update");
    commands->add_flag("--check", o->check, "Exit 1 when the document's reference differs from the commands' help");
    commands->add_flag("--update", o->update, "Rewrite the document's reference from the commands' help");

    return [o, &global, &app, commands] {
        if (commands->parsed()) {
            const std::string reference = commandReference(app);
            if (o->commandsDocument.empty()) {
                std::fputs(reference.c_str(), stdout);
                return;
            }
            if (o->check == o->update) throw CommandExit{2, "with a document, give --check or --update"};
            const std::string& path = o->commandsDocument;
            const std::string current = readFileBytes(path), updated = withCommandReference(current, reference, path);
            if (updated == current) return;
            if (o->check)
                throw CommandExit{1, path + ": the command reference is stale (vfield help commands --update " + path + ")"};
            writeTextAtomically(path, updated);
            log(global, path + ": updated the command reference");
            return;
        }
        const std::vector<FieldTable> tables = sceneKeyTables();
        if (o->documents.empty()) {
            for (const FieldTable& table : tables)
                std::printf("### `%s`\n\n%s\n", table.title.c_str(), markdownTable(table).c_str());
            return;
        }
        if (o->check == o->update) throw CommandExit{2, "with documents, give --check or --update"};
        std::vector<std::string> problems, absentEverywhere;
        bool first = true;
        for (const std::string& path : o->documents) {
            const KeyTableUpdate update = updateKeyTables(readFileBytes(path), tables);
            if (!update.unknown.empty()) problems.push_back(path + ": no table is titled " + joined(update.unknown));
            if (o->update) {
                if (update.text != readFileBytes(path)) writeTextAtomically(path, update.text);
                if (!update.stale.empty()) log(global, path + ": updated " + joined(update.stale));
            } else if (!update.stale.empty()) {
                problems.push_back(path + ": stale tables " + joined(update.stale) + " (vfield help keys --update " + path + ")");
            }
            if (first) absentEverywhere = update.absent;
            else {
                std::vector<std::string> still;
                for (const std::string& t : absentEverywhere)
                    if (std::find(update.absent.begin(), update.absent.end(), t) != update.absent.end()) still.push_back(t);
                absentEverywhere = still;
            }
            first = false;
        }
        if (o->complete && !absentEverywhere.empty())
            problems.push_back("no document holds the tables " + joined(absentEverywhere));
        if (!problems.empty()) {
            for (std::size_t i = 0; i + 1 < problems.size(); ++i) std::fprintf(stderr, "vfield help: %s\n", problems[i].c_str());
            throw CommandExit{1, problems.back()};
        }
    };
}

} // namespace vfield::cli
