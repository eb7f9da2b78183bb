// `arco <command> [options]`: the command-line front end (cli/app.h builds the app from
// the commands that register themselves, command.h).
#include "arco/cli/app.h"

int main(int argc, char** argv) { return arco::cli::Main(argc, argv); }
