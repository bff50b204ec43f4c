// The `lamina` executable: the command-line interface of cli/run.cpp.
#include "cli/commands.h"

int main(int argc, char** argv) {
    return lamina::cli::run(argc, argv);
}
