#pragma once
// The folders a run created for its --out (core internals: io.cpp creates them, output_run.cpp ends the run). A
// run that ends without committing (a refusal after the folder was made, an error) removes what it created and
// left empty, so that a refusal creates nothing; a folder that holds anything (another run's outputs, a user's
// file) stays.
#include <filesystem>

namespace geomint::detail {

// The outermost folder of `target` that does not exist yet ("" when target exists): what creating it makes.
std::filesystem::path first_missing_folder(const std::filesystem::path& target);
// The run into `target` created the folders from `outermost` down to target (or none: "").
void note_created_folders(const std::filesystem::path& target, const std::filesystem::path& outermost);
// Removes those folders, innermost first, while they are empty; forgets them either way. Called when a run ends
// without a commit, and when the folder could not be made a run.
void remove_created_folders();
// The run committed: its folders are the user's now.
void keep_created_folders();

}  // namespace geomint::detail
