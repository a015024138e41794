/**
 * @file fuzz_mutator.h
 * @brief Seeded generators of hostile input for the fuzz suite: text and byte mutations
 *        (truncation, bit flips, NUL bytes, huge and non-finite numbers, lost, doubled and
 *        garbage lines, crossing rings), and the bookkeeping every fuzz test shares.
 */
#pragma once

#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace fuzz
{
/**
 * @brief Cases for one generator: @p share of FDML_FUZZ_CASES when that is set (make fuzz),
 *        else @p bounded (the fixed-seed part run by make test). At least 1.
 */
int caseCount(double share, int bounded);

/// Numbers a hostile file might hold: huge, tiny, non-finite, overflowing integers.
const std::vector<std::string>& hostileNumbers();

/// Random mutations with a fixed seed (the same seed gives the same cases).
class Mutator
{
public:
  explicit Mutator(std::uint64_t seed) : rng_(seed)
  {}

  /// An integer in [lo, hi].
  int uniform(int lo, int hi)
  {
    return std::uniform_int_distribution<int>(lo, hi)(rng_);
  }

  /// 1 to 3 mutations of a text file, line- and number-aware; @p description names them.
  std::string mutateText(const std::string& text, std::string& description);

  /// 1 to 3 byte-level mutations of a binary file (truncation, bit flips, NUL and random bytes,
  /// header numbers replaced by hostile ones); @p description names them.
  std::string mutateBytes(const std::string& bytes, std::string& description);

private:
  std::string mutateTextOnce(const std::string& text, std::string& description);
  std::string mutateBytesOnce(const std::string& bytes, std::string& description);
  std::string replaceNumber(const std::string& text, std::string& description);

  std::mt19937_64 rng_;
};

/// Outcome counts and the first failures of one fuzz test; report() prints one line.
struct Tally
{
  explicit Tally(const std::string& name_) : name(name_)
  {}

  std::string name;
  int cases = 0;
  int accepted = 0;  ///< loaded (or ran) successfully
  int rejected = 0;  ///< refused with a proper message
  std::vector<std::string> failures;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

  void fail(const std::string& what)
  {
    if (failures.size() < 20)
    {
      failures.push_back(what);
    }
    else if (failures.size() == 20)
    {
      failures.push_back("...");
    }
  }
  /// "fuzz NAME: N cases (A accepted, R rejected), F failures, T s".
  std::string report() const;
};

/// Writes @p bytes to @p path (binary). @return path
std::string writeFile(const std::string& path, const std::string& bytes);

/// The whole content of a file ("" when it cannot be read).
std::string readFile(const std::string& path);

}  // namespace fuzz
}  // namespace fdml_localization
