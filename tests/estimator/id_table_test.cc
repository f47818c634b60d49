#include "estimator/id_table.h"

#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace roamlab::estimator {
namespace {

using Table = IdTable<std::string>;

// The table against a std::map holding the same elements: walks both ways, look-ups, lower bounds.
void ExpectSameAs(const std::map<Table::Id, std::string>& oracle, const Table& table, Table::Id max_id) {
  ASSERT_EQ(table.size(), oracle.size());
  EXPECT_EQ(table.empty(), oracle.empty());
  std::vector<std::pair<Table::Id, std::string>> forward, backward;
  for (const auto& [id, value] : table) forward.emplace_back(id, value);
  for (auto it = table.rbegin(); it != table.rend(); ++it) backward.emplace_back(it->first, it->second);
  const std::vector<std::pair<Table::Id, std::string>> expected(oracle.begin(), oracle.end());
  EXPECT_EQ(forward, expected);
  const std::vector<std::pair<Table::Id, std::string>> reversed(expected.rbegin(), expected.rend());
  EXPECT_EQ(backward, reversed);
  for (Table::Id id = -3; id <= max_id + 3; ++id) {
    const auto it = oracle.find(id);
    const std::string* found = table.Find(id);
    ASSERT_EQ(found != nullptr, it != oracle.end()) << id;
    if (found != nullptr) {
      EXPECT_EQ(*found, it->second) << id;
    }
    EXPECT_EQ(table.count(id), oracle.count(id)) << id;
    const auto bound = table.lower_bound(id);
    const auto expected_bound = oracle.lower_bound(id);
    ASSERT_EQ(bound == table.end(), expected_bound == oracle.end()) << id;
    if (bound != table.end()) {
      EXPECT_EQ(bound->first, expected_bound->first) << id;
    }
  }
}

TEST(IdTableTest, WalksAndLooksUpAsAMapThroughRandomAddsAndErases) {
  std::mt19937 rng(7);
  Table table;
  std::map<Table::Id, std::string> oracle;
  Table::Id next = 5;
  for (int step = 0; step < 4000; ++step) {
    // Mostly adds early, mostly erases late (the table empties and refills), with gaps in the ids.
    const bool add = oracle.empty() || std::uniform_int_distribution<int>(0, 99)(rng) < (step < 2000 ? 70 : 35);
    if (add) {
      next += std::uniform_int_distribution<int>(1, 3)(rng);
      table.Add(next, std::to_string(next));
      oracle[next] = std::to_string(next);
    } else {
      auto it = oracle.begin();
      std::advance(it, std::uniform_int_distribution<std::size_t>(0, oracle.size() - 1)(rng));
      table.Erase(it->first);
      oracle.erase(it);
    }
    if (step % 97 == 0) ExpectSameAs(oracle, table, next);
  }
  ExpectSameAs(oracle, table, next);
}

TEST(IdTableTest, SlidingWindowKeepsItsElementsInPlace) {
  // A window of 300 ids sliding over 100 000, with one element from the start kept all along (a calibration
  // parameter): the kept element and the window's never move, and the walk sees exactly them.
  Table table;
  std::string& kept = table.Add(0, "parameter");
  const std::string* kept_address = &kept;
  std::map<Table::Id, const std::string*> addresses;
  for (Table::Id id = 1; id < 100000; ++id) {
    addresses[id] = &table.Add(id, std::to_string(id));
    if (id > 300) {
      table.Erase(id - 300);
      addresses.erase(id - 300);
    }
  }
  EXPECT_EQ(table.Find(0), kept_address);
  EXPECT_EQ(table.size(), 301u);
  for (const auto& [id, address] : addresses) ASSERT_EQ(table.Find(id), address) << id;
  std::vector<Table::Id> walked;
  for (const auto& [id, value] : table) walked.push_back(id);
  ASSERT_EQ(walked.size(), 301u);
  EXPECT_EQ(walked.front(), 0);
  EXPECT_EQ(walked[1], 100000 - 300);
  EXPECT_EQ(walked.back(), 99999);
  EXPECT_EQ(table.rbegin()->first, 99999);
  // Without the parameter the released chunks at the front go, and the walk starts at the window.
  table.Erase(0);
  EXPECT_EQ(table.begin()->first, 100000 - 300);
  EXPECT_EQ(table.lower_bound(0)->first, 100000 - 300);
}

TEST(IdTableDeathTest, RejectsAnIdNotAfterTheLastAndErasingAMissingOne) {
  Table table;
  table.Add(10, "a");
  EXPECT_DEATH(table.Add(10, "b"), "id 10 added after 10");
  EXPECT_DEATH(table.Erase(11), "no element 11");
}

}  // namespace
}  // namespace roamlab::estimator
