#pragma once
// The version and git hash this build was made from (provenance in manifests and stats). They
// live in one generated file (build_info.cpp.in), so a new commit recompiles that file only.
namespace rtsim {

const char* rtsim_version();
const char* rtsim_git_hash();

}  // namespace rtsim
