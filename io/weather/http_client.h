// HTTP(S) GET with libcurl (Debian: libcurl4-openssl-dev), for the daemon's
// weather-forecast fetch. One call is one request on its own easy handle:
// a connect limit and a total limit, redirects followed (at most 5), the
// body capped, no signals (curl's resolver timeouts use none), and an abort
// flag polled during the transfer so that a stopping daemon never waits for
// a slow server.
#pragma once

#include <atomic>
#include <string>

namespace pvtwin {

struct HttpResponse {
  enum class Outcome {
    kOk,           // a response with status 2xx
    kHttpError,    // a response with another status (404, 500, 503, ...)
    kUnreachable,  // no connection: refused, DNS, connect timeout, TLS
    kTimeout,      // connected, but the whole transfer ran over its limit
    kBroken,       // the transfer broke off (connection closed early, body too large)
    kAborted,      // *abort was set
  } outcome = Outcome::kUnreachable;
  long status = 0;    // HTTP status when a response came
  std::string body;   // the response body (also for HTTP errors, capped)
  std::string error;  // curl's message, or "HTTP 503"
};

struct HttpOptions {
  double connect_timeout_s = 10.0;
  double total_timeout_s = 30.0;
  std::size_t max_body_bytes = 16u << 20;  // 16 MiB: a 16-day 15-min forecast is < 2 MiB
};

HttpResponse HttpGet(const std::string& url, const HttpOptions& options,
                     const std::atomic<bool>* abort);

// url with the values of credential-like query parameters (apikey, api_key,
// key, token, access_token, password) replaced by "***", for log lines and
// stored sources: a commercial weather API's key must not end up in the
// journal or the database.
std::string UrlForLogs(const std::string& url);

// "connection refused" etc.: the outcome as a word for log lines.
const char* OutcomeName(HttpResponse::Outcome outcome);

}  // namespace pvtwin
