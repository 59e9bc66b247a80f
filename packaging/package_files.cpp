// Writes the files the packages carry that are drawn from the program itself, so they never
// drift from it: the manual pages terralux.1 and terralux-bake.1 (from the help entries and the
// parameter table) and the project JSON Schema.
//   terralux-package-files OUTDIR VERSION DATE
#include <fstream>
#include <iostream>

#include "CommandLineHelp.h"
#include "ParameterTable.h"

int main(int argc, char** argv) {
    if (argc != 4) {
        std::cerr << "usage: terralux-package-files OUTDIR VERSION DATE\n";
        return 2;
    }
    const std::string dir = argv[1], version = argv[2], date = argv[3];
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream out(dir + "/" + name, std::ios::binary);
        out << text;
        if (!out.flush()) {
            std::cerr << "terralux-package-files: " << dir << "/" << name << ": cannot write\n";
            std::exit(3);
        }
    };
    using namespace terralux;
    write("terralux.1", manualPage(commandLineHelp(Binary::Authoring), version, date));
    write("terralux-bake.1", manualPage(commandLineHelp(Binary::Headless), version, date));
    write("terralux.schema.json", projectSchema().dump(2) + "\n");
    return 0;
}
