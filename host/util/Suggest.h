#pragma once
// "Did you mean": the known name closest to a misspelt one, for the one-line
// errors of unknown scene keys, command-line flags and some values (film.view).
#include <string>
#include <vector>

namespace pyrolume {

// Optimal string alignment distance: insertions, deletions, substitutions and
// swaps of two neighbours each cost 1.
size_t edit_distance(const std::string& a, const std::string& b);

// The entry of `known` nearest to `word`, when it is near enough to be a typo
// of it (at most 1 edit for words of up to 4 characters, 2 up to 8, else 3;
// case ignored); "" otherwise. Ties go to the first in `known`.
std::string closest_name(const std::string& word, const std::vector<std::string>& known);

// " (did you mean \"NAME\"?)" for closest_name, or "" when none is near.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& known);

// The reason an unknown value is refused: `must be one of "a", "b", got "x"`,
// and with `suggest` the " (did you mean ...?)" of the nearest allowed name.
std::string not_one_of(const std::string& word, const std::vector<std::string>& allowed, bool suggest = false);

}  // namespace pyrolume
