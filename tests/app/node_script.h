// node_script.h — runs a Node.js script of scripts/ (the Khronos validator harness,
// three_check.mjs) with the npm package it needs, as scripts/setup.sh installs it into
// .tools/node. A missing node or package fails the test, never skips it.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace sylva::test {

inline ProcessResult run_node_script(const std::string& script, const std::string& package,
                                     const std::vector<std::string>& args) {
  const std::string source = SYLVA_SOURCE_DIR;
  const std::filesystem::path installed =
      std::filesystem::path(source) / ".tools/node/node_modules" / package / "package.json";
  if (!std::filesystem::exists(installed)) {
    ADD_FAILURE() << package << " is not installed (" << installed.string() << " is missing): run scripts/setup.sh";
    return {};
  }
  std::vector<std::string> argv = {"node", source + "/scripts/" + script};
  argv.insert(argv.end(), args.begin(), args.end());
  try {
    return run_process(argv, {}, 240);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "cannot run node (install Node.js with scripts/setup.sh): " << e.what();
    return {};
  }
}

}  // namespace sylva::test
