// vfield help keys: the documentation of every scene key, derived from the
// options' declarations; --update and --check keep documents' tables
// (scenes/README.md) equal to it.

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

} // namespace

Runner registerHelp(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        std::vector<std::string> documents;
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

    return [o, &global] {
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
