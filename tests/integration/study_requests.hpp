#pragma once
// Studies through the API: submitting a plan and waiting for its table.
#include <gtest/gtest.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "grip_process.hpp"

namespace grip::testing {

inline json post_study(const Api& api, const json& request, int status) {
  const auto r = api.post_json("/v1/studies", request.dump());
  if (!r) throw std::runtime_error("no response");
  EXPECT_EQ(r->status, status) << r->body;
  json body = json::parse(r->body);
  // A refused plan has no id to wait on: stop the test here (its server and folder are cleaned).
  if (status == 201 && !body.contains("id")) throw std::runtime_error("no study was made: " + r->body);
  return body;
}

// The study's document once it is successful, or as it stands after 2 minutes.
inline json study_when_successful(const Api& api, const std::string& id) {
  json study;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    study = json::parse(api.get("/v1/studies/" + id)->body);
  } while (study["status"] != "successful" && std::chrono::steady_clock::now() < deadline);
  return study;
}

}  // namespace grip::testing
