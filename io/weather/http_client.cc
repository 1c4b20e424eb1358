#include "io/weather/http_client.h"

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "config/shared_library.h"

namespace pvtwin {

namespace {

// libcurl's functions, from libcurl.so.4 loaded by the first fetch
// (config/shared_library.h); members drop the curl_ prefix, so that calls
// do not meet curl.h's type-checking macros of the same names.
// clang-format off
#define PVTWIN_LIBCURL_FUNCTIONS(X) \
  X(global_init) \
  X(easy_init) \
  X(easy_setopt) \
  X(easy_perform) \
  X(easy_getinfo) \
  X(easy_cleanup) \
  X(easy_strerror)
// clang-format on

struct LibcurlApi {
#define PVTWIN_LIBCURL_MEMBER(name) decltype(&::curl_##name) name = nullptr;
  PVTWIN_LIBCURL_FUNCTIONS(PVTWIN_LIBCURL_MEMBER)
#undef PVTWIN_LIBCURL_MEMBER
};

// Loaded, bound and curl_global_init'ed once; throws std::runtime_error
// when libcurl.so.4 is missing.
const LibcurlApi& Libcurl() {
  static const LibcurlApi api = [] {
    static const SharedLibrary library("libcurl.so.4", "libcurl4");
    LibcurlApi bound;
#define PVTWIN_LIBCURL_BIND(name) library.Bind(&bound.name, "curl_" #name);
    PVTWIN_LIBCURL_FUNCTIONS(PVTWIN_LIBCURL_BIND)
#undef PVTWIN_LIBCURL_BIND
    bound.global_init(CURL_GLOBAL_DEFAULT);
    return bound;
  }();
  return api;
}

struct Transfer {
  std::string* body;
  std::size_t max_bytes;
  bool too_large = false;
  const std::atomic<bool>* abort;
};

std::size_t OnData(char* data, std::size_t size, std::size_t count, void* user) {
  auto* t = static_cast<Transfer*>(user);
  const std::size_t n = size * count;
  if (t->body->size() + n > t->max_bytes) {
    t->too_large = true;
    return 0;  // curl stops with CURLE_WRITE_ERROR
  }
  t->body->append(data, n);
  return n;
}

int OnProgress(void* user, curl_off_t, curl_off_t, curl_off_t, curl_off_t) {
  const auto* t = static_cast<const Transfer*>(user);
  return t->abort != nullptr && t->abort->load() ? 1 : 0;  // non-zero aborts the transfer
}

HttpResponse::Outcome OutcomeOf(CURLcode rc) {
  switch (rc) {
    case CURLE_COULDNT_RESOLVE_HOST:
    case CURLE_COULDNT_RESOLVE_PROXY:
    case CURLE_COULDNT_CONNECT:
    case CURLE_SSL_CONNECT_ERROR:
    case CURLE_PEER_FAILED_VERIFICATION:
      return HttpResponse::Outcome::kUnreachable;
    case CURLE_OPERATION_TIMEDOUT:
      return HttpResponse::Outcome::kTimeout;
    case CURLE_ABORTED_BY_CALLBACK:
      return HttpResponse::Outcome::kAborted;
    default:
      return HttpResponse::Outcome::kBroken;
  }
}

}  // namespace

std::string UrlForLogs(const std::string& url) {
  static const char* const kSecretKeys[] = {"apikey", "api_key",      "key",
                                            "token",  "access_token", "password"};
  const std::size_t query = url.find('?');
  if (query == std::string::npos) return url;
  std::string out = url.substr(0, query + 1);
  std::size_t at = query + 1;
  while (at <= url.size()) {
    std::size_t end = url.find('&', at);
    if (end == std::string::npos) end = url.size();
    const std::string pair = url.substr(at, end - at);
    const std::size_t eq = pair.find('=');
    std::string name = pair.substr(0, eq);
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool secret =
        eq != std::string::npos &&
        std::find(std::begin(kSecretKeys), std::end(kSecretKeys), name) != std::end(kSecretKeys);
    out += secret ? pair.substr(0, eq + 1) + "***" : pair;
    if (end < url.size()) out += '&';
    at = end + 1;
  }
  return out;
}

const char* OutcomeName(HttpResponse::Outcome outcome) {
  switch (outcome) {
    case HttpResponse::Outcome::kOk:
      return "ok";
    case HttpResponse::Outcome::kHttpError:
      return "HTTP error";
    case HttpResponse::Outcome::kUnreachable:
      return "unreachable";
    case HttpResponse::Outcome::kTimeout:
      return "timed out";
    case HttpResponse::Outcome::kBroken:
      return "transfer broken off";
    case HttpResponse::Outcome::kAborted:
      return "aborted";
  }
  return "?";
}

HttpResponse HttpGet(const std::string& url, const HttpOptions& options,
                     const std::atomic<bool>* abort) {
  HttpResponse response;
  const LibcurlApi* api = nullptr;
  try {
    api = &Libcurl();
  } catch (const std::runtime_error& e) {
    response.outcome = HttpResponse::Outcome::kBroken;
    response.error = e.what();
    return response;
  }
  CURL* curl = api->easy_init();
  if (curl == nullptr) {
    response.outcome = HttpResponse::Outcome::kBroken;
    response.error = "curl_easy_init failed";
    return response;
  }
  Transfer transfer{&response.body, options.max_body_bytes, false, abort};
  char error_buffer[CURL_ERROR_SIZE] = {};
  api->easy_setopt(curl, CURLOPT_URL, url.c_str());
  api->easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  api->easy_setopt(curl, CURLOPT_FOLLOWLOCATION, 1L);
  api->easy_setopt(curl, CURLOPT_MAXREDIRS, 5L);
  api->easy_setopt(curl, CURLOPT_PROTOCOLS_STR, "http,https");
  api->easy_setopt(curl, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
  api->easy_setopt(
      curl, CURLOPT_CONNECTTIMEOUT_MS,
      static_cast<long>(std::min(options.connect_timeout_s, options.total_timeout_s) * 1000.0));
  api->easy_setopt(curl, CURLOPT_TIMEOUT_MS, static_cast<long>(options.total_timeout_s * 1000.0));
  api->easy_setopt(curl, CURLOPT_USERAGENT, "pvtwin");
  api->easy_setopt(curl, CURLOPT_ACCEPT_ENCODING, "");  // whatever curl can decode
  api->easy_setopt(curl, CURLOPT_WRITEFUNCTION, &OnData);
  api->easy_setopt(curl, CURLOPT_WRITEDATA, &transfer);
  api->easy_setopt(curl, CURLOPT_XFERINFOFUNCTION, &OnProgress);
  api->easy_setopt(curl, CURLOPT_XFERINFODATA, &transfer);
  api->easy_setopt(curl, CURLOPT_NOPROGRESS, 0L);
  api->easy_setopt(curl, CURLOPT_ERRORBUFFER, error_buffer);
  const CURLcode rc = api->easy_perform(curl);
  api->easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &response.status);
  api->easy_cleanup(curl);
  if (rc != CURLE_OK) {
    response.outcome = transfer.too_large ? HttpResponse::Outcome::kBroken : OutcomeOf(rc);
    response.error = transfer.too_large
                         ? "response body over " + std::to_string(options.max_body_bytes) + " bytes"
                         : (error_buffer[0] != '\0' ? std::string(error_buffer)
                                                    : std::string(api->easy_strerror(rc)));
    return response;
  }
  if (response.status < 200 || response.status >= 300) {
    response.outcome = HttpResponse::Outcome::kHttpError;
    response.error = "HTTP " + std::to_string(response.status);
    return response;
  }
  response.outcome = HttpResponse::Outcome::kOk;
  return response;
}

}  // namespace pvtwin
