#include "fuzz_mutator.h"

#include <cctype>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace fuzz
{
int caseCount(double share, int bounded)
{
  const char* total = std::getenv("FDML_FUZZ_CASES");
  if (total == nullptr || *total == '\0')
  {
    return std::max(bounded, 1);
  }
  const double n = std::strtod(total, nullptr);
  return std::max(1, static_cast<int>(std::min(n * share, 1e8)));
}

const std::vector<std::string>& hostileNumbers()
{
  static const std::vector<std::string> numbers = {
    "1e19",   "-1e19",      "1e308",       "1e309",
    "-1e400", "1e-400",     "nan",         "-nan",
    "inf",    "-inf",       "0x1p1023",    "1.5e9",
    "1e9",    "-0",         "0",           "1e-320",
    "",       "4294967296", "-2147483649", "99999999999999999999999",
    "1e+",    ".",          "-",           "+e5",
    "1,5",    "1 5",        "0x",          "1e2147483648",
  };
  return numbers;
}

std::string Mutator::mutateText(const std::string& text, std::string& description)
{
  std::string out = text;
  for (int n = uniform(1, 3); n > 0; --n)
  {
    out = mutateTextOnce(out, description);
  }
  return out;
}

std::string Mutator::mutateBytes(const std::string& bytes, std::string& description)
{
  std::string out = bytes;
  for (int n = uniform(1, 3); n > 0; --n)
  {
    out = mutateBytesOnce(out, description);
  }
  return out;
}

std::string Mutator::replaceNumber(const std::string& text, std::string& description)
{
  std::vector<std::pair<std::size_t, std::size_t>> numbers;  // [begin, end)
  for (std::size_t i = 0; i < text.size();)
  {
    if (std::isdigit(static_cast<unsigned char>(text[i])))
    {
      std::size_t j = i;
      while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || text[j] == '.' ||
                                 text[j] == 'e' || text[j] == 'E' || text[j] == '-' || text[j] == '+'))
      {
        ++j;
      }
      numbers.emplace_back(i, j);
      i = j;
    }
    else
    {
      ++i;
    }
  }
  if (numbers.empty())
  {
    return text;
  }
  const auto& span = numbers[static_cast<std::size_t>(uniform(0, static_cast<int>(numbers.size()) - 1))];
  const std::string& hostile = hostileNumbers()[static_cast<std::size_t>(uniform(0, hostileNumbers().size() - 1))];
  description += " number->'" + hostile + "'";
  return text.substr(0, span.first) + hostile + text.substr(span.second);
}

std::string Mutator::mutateTextOnce(const std::string& text, std::string& description)
{
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
  {
    lines.push_back(line);
  }
  auto join = [](const std::vector<std::string>& parts) {
    std::string out;
    for (const std::string& p : parts)
    {
      out += p + "\n";
    }
    return out;
  };
  const int line = lines.empty() ? 0 : uniform(0, static_cast<int>(lines.size()) - 1);
  switch (uniform(0, 7))
  {
    case 0:
    case 1:
      return replaceNumber(text, description);
    case 2:
      description += " line-deleted";
      if (!lines.empty())
      {
        lines.erase(lines.begin() + line);
      }
      return join(lines);
    case 3:
      description += " line-doubled";
      if (!lines.empty())
      {
        lines.insert(lines.begin() + line, lines[line]);
      }
      return join(lines);
    case 4:
      description += " crossing-ring";
      lines.insert(lines.begin() + line, "\n0.5 0.5\n3 3\n3 0.5\n0.5 3\n");
      return join(lines);
    case 5: {
      description += " garbage-line";
      std::string garbage;
      for (int n = uniform(0, 12); n > 0; --n)
      {
        garbage += static_cast<char>(uniform(1, 255));
      }
      lines.insert(lines.begin() + line, garbage);
      return join(lines);
    }
    default:
      return mutateBytesOnce(text, description);
  }
}

std::string Mutator::mutateBytesOnce(const std::string& bytes, std::string& description)
{
  std::string out = bytes;
  const std::size_t at = out.empty() ? 0 : static_cast<std::size_t>(uniform(0, static_cast<int>(out.size()) - 1));
  switch (uniform(0, 5))
  {
    case 0:
      description += " truncated@" + std::to_string(at);
      out.resize(at);
      break;
    case 1:
      description += " bitflip@" + std::to_string(at);
      if (!out.empty())
      {
        out[at] = static_cast<char>(out[at] ^ (1 << uniform(0, 7)));
      }
      break;
    case 2:
      description += " nul@" + std::to_string(at);
      out.insert(at, 1, '\0');
      break;
    case 3:
      description += " byte@" + std::to_string(at);
      if (!out.empty())
      {
        out[at] = static_cast<char>(uniform(0, 255));
      }
      break;
    case 4:
      // Numbers early in the file are header fields (PGM size, maxval, YAML keys).
      return replaceNumber(out.substr(0, 64), description) + (out.size() > 64 ? out.substr(64) : "");
    default:
      description += " appended";
      for (int n = uniform(1, 64); n > 0; --n)
      {
        out += static_cast<char>(uniform(0, 255));
      }
      break;
  }
  return out;
}

std::string Tally::report() const
{
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream os;
  os.precision(3);
  os << "fuzz " << name << ": " << cases << " cases (" << accepted << " accepted, " << rejected << " rejected), "
     << failures.size() << " failures, " << seconds << " s";
  return os.str();
}

std::string writeFile(const std::string& path, const std::string& bytes)
{
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

std::string readFile(const std::string& path)
{
  std::ostringstream s;
  s << std::ifstream(path, std::ios::binary).rdbuf();
  return s.str();
}

}  // namespace fuzz
}  // namespace fdml_localization
