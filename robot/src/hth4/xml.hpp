// rcb4 — private helpers of the HTH4 readers and writers: pugixml documents read with errors that
// name the file, the line and the element, and written as .NET's XmlSerializer writes them
// (hth4-files.md §1: `<?xml version="1.0"?>`, both namespaces on the root, CRLF, two spaces).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <pugixml.hpp>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

namespace rcb4::robot::hth4::detail {

inline constexpr const char* xsi_namespace = "http://www.w3.org/2001/XMLSchema-instance";
inline constexpr const char* xsd_namespace = "http://www.w3.org/2001/XMLSchema";

/** A parsed document and what errors need to name a place in it. */
class xml_in {
 public:
  /** Parses @p text (at most max_file_bytes); @p root must be its root element's name (one of @p roots, '|'-separated).
   */
  xml_in(std::string_view text, std::string source, std::string_view roots, std::string_view what)
      : source_(std::move(source)), text_(text) {
    if (text.size() > max_file_bytes)
      throw profile_error(source_, "is " + std::to_string(text.size() >> 20) + " MiB; " + std::string(what) +
                                       " is far smaller (this reader stops at " + std::to_string(max_file_bytes >> 20) +
                                       " MiB)");
    // HTH4 writes UTF-8 (hth4-files.md §1); anything else (Shift-JIS from another tool) would come
    // out as garbled names in every file made from it.
    for (std::size_t i = 0; i < text.size();) {
      const auto c = static_cast<unsigned char>(text[i]);
      const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
      bool ok = n != 0 && i + n <= text.size();
      for (std::size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(text[i + k]) >> 6) == 2;
      if (!ok)
        throw profile_error(at(i),
                            "not UTF-8 (byte " + std::to_string(i) +
                                "): HeartToHeart4 writes its files in UTF-8; convert it (iconv -f SHIFT_JIS -t UTF-8)");
      i += n;
    }
    const auto r = doc_.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!r) throw profile_error(at(static_cast<std::size_t>(r.offset)), std::string("not XML: ") + r.description());
    root_ = doc_.document_element();
    bool known = false;
    for (std::size_t b = 0; b <= roots.size();) {
      const auto e = std::min(roots.find('|', b), roots.size());
      known = known || roots.substr(b, e - b) == root_.name();
      b = e + 1;
    }
    if (!known)
      throw profile_error(
          where(root_), std::string("the root element is <") + root_.name() + ">, not <" + [&] {
            std::string names(roots);
            for (std::size_t k; (k = names.find('|')) != std::string::npos;) names.replace(k, 1, "> or <");
            return names;
          }() + ">: not " + std::string(what));
  }
  /** The root element. */
  pugi::xml_node root() const { return root_; }
  /** "FILE:LINE" of byte @p offset. */
  std::string at(std::size_t offset) const {
    offset = std::min(offset, text_.size());
    std::size_t line = 1;
    for (std::size_t i = 0; i < offset; ++i) line += text_[i] == '\n';
    return source_ + ":" + std::to_string(line);
  }
  /** The line of @p n (1-based; 0 when unknown). */
  unsigned line_of(const pugi::xml_node& n) const {
    const auto off = n.offset_debug();
    if (off < 0) return 0;
    const auto end = std::min(static_cast<std::size_t>(off), text_.size());
    return static_cast<unsigned>(std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(end), '\n') + 1);
  }
  /** "FILE:LINE: <Element>" of @p n. */
  std::string where(const pugi::xml_node& n) const {
    const auto off = n.offset_debug();
    return (off >= 0 ? at(static_cast<std::size_t>(off)) : source_) + ": <" + n.name() + ">";
  }
  /** Throws the error @p what at @p n. */
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& what) const {
    throw profile_error(where(n), what);
  }
  /** The child @p name of @p n; an error when it is missing. */
  pugi::xml_node need(const pugi::xml_node& n, const char* name) const {
    auto c = n.child(name);
    if (!c) fail(n, std::string("has no <") + name + ">");
    return c;
  }
  /** The text of child @p name (empty when the element is empty); an error when it is missing. */
  std::string text(const pugi::xml_node& n, const char* name) const { return need(n, name).child_value(); }
  /** The integer in child @p name, within [@p lo, @p hi]. */
  long long integer(const pugi::xml_node& n, const char* name, long long lo, long long hi) const {
    return integer_of(need(n, name), lo, hi);
  }
  /** The integer text of @p c, within [@p lo, @p hi]. */
  long long integer_of(const pugi::xml_node& c, long long lo, long long hi) const {
    const std::string_view t = c.child_value();
    long long v = 0;
    const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc{} || p != t.data() + t.size())
      fail(c, std::string("'").append(t.substr(0, 40)).append("' is not an integer"));  // (+ warns falsely: GCC 12 -O3)
    if (v < lo || v > hi)
      fail(c, std::to_string(v) + " is out of range (" + std::to_string(lo) + ".." + std::to_string(hi) + ")");
    return v;
  }
  /** The value of attribute xsi:type of @p n (empty when absent). */
  static std::string_view type_of(const pugi::xml_node& n) { return n.attribute("xsi:type").value(); }
  /** Checks @p n has xsi:type @p type. */
  void need_type(const pugi::xml_node& n, std::string_view type) const {
    if (type_of(n) != type) fail(n, "xsi:type is '" + std::string(type_of(n)) + "', not '" + std::string(type) + "'");
  }
  /** The children of @p n named @p name, counted. */
  static std::size_t count(const pugi::xml_node& n, const char* name) {
    std::size_t k = 0;
    for (auto c = n.child(name); c; c = c.next_sibling(name)) ++k;
    return k;
  }
  /** @p n as written (for elements kept without a meaning: GUI colours, <Anchors>). */
  static std::string raw(const pugi::xml_node& n) {
    if (!n) return {};
    std::ostringstream s;
    n.print(s, "", pugi::format_raw);
    return s.str();
  }
  /** The file's name, for messages. */
  const std::string& source() const { return source_; }

 private:
  std::string source_;
  std::string_view text_;
  pugi::xml_document doc_;
  pugi::xml_node root_;
};

/** A new document with the root @p name carrying both namespaces (§1). */
inline pugi::xml_node new_root(pugi::xml_document& doc, const char* name) {
  auto decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  auto root = doc.append_child(name);
  root.append_attribute("xmlns:xsi") = xsi_namespace;
  root.append_attribute("xmlns:xsd") = xsd_namespace;
  return root;
}
/** Appends <name>text</name> (an empty element when @p text is empty). */
inline pugi::xml_node add(pugi::xml_node n, const char* name, std::string_view text) {
  auto c = n.append_child(name);
  if (!text.empty()) c.text().set(std::string(text).c_str());
  return c;
}
/** Appends <name>number</name>. */
inline pugi::xml_node add(pugi::xml_node n, const char* name, long long v) { return add(n, name, std::to_string(v)); }
/**
 * Appends <DictionaryEntry><Key xsi:type="@p key_type">key</Key><Value xsi:type="@p value_type">
 * to @p coll and returns the Value (§1); no Value, and a null node, when @p value_type is null.
 */
inline pugi::xml_node add_entry(pugi::xml_node coll, std::string_view key, const char* value_type,
                                const char* key_type = "xsd:string") {
  auto e = coll.append_child("DictionaryEntry");
  add(e, "Key", key).prepend_attribute("xsi:type") = key_type;
  if (!value_type) return {};
  auto v = e.append_child("Value");
  v.append_attribute("xsi:type") = value_type;
  return v;
}
/** Appends the elements in @p raw (kept from a read) to @p n. */
inline void add_raw(pugi::xml_node n, const std::string& raw) {
  if (!raw.empty()) n.append_buffer(raw.data(), raw.size());
}
/** The document as XmlSerializer writes it: two-space indentation, CRLF. */
inline std::string serialize(const pugi::xml_document& doc) {
  std::ostringstream s;
  doc.save(s, "  ", pugi::format_indent, pugi::encoding_utf8);
  std::string out;
  for (const char c : s.str()) {
    if (c == '\n') out += '\r';
    out += c;
  }
  while (out.size() >= 2 && out.ends_with("\r\n")) out.resize(out.size() - 2);
  return out;
}
/** Reads @p path whole, at most max_file_bytes. */
inline std::string read_file(const std::filesystem::path& path, std::string_view what) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw profile_error(path.string(), "cannot read: " + ec.message());
  if (size > max_file_bytes)
    throw profile_error(path.string(), "is " + std::to_string(size >> 20) + " MiB; " + std::string(what) +
                                           " is far smaller (this reader stops at " +
                                           std::to_string(max_file_bytes >> 20) + " MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw profile_error(path.string(), "cannot read");
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  return text;
}
/** Writes @p text to @p path (replacing it only once it is whole). */
inline void write_file(const std::filesystem::path& path, const std::string& text) {
  const auto tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(text.data(), static_cast<std::streamsize>(text.size())) || !out.flush())
      throw profile_error(path.string(), "cannot write");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw profile_error(path.string(), "cannot write: " + ec.message());
}

}  // namespace rcb4::robot::hth4::detail
