#include "io/http_client.h"

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <mutex>

namespace pvtwin {

namespace {

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
  static std::once_flag init;
  std::call_once(init, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
  HttpResponse response;
  CURL* curl = curl_easy_init();
  if (curl == nullptr) {
    response.outcome = HttpResponse::Outcome::kBroken;
    response.error = "curl_easy_init failed";
    return response;
  }
  Transfer transfer{&response.body, options.max_body_bytes, false, abort};
  char error_buffer[CURL_ERROR_SIZE] = {};
  curl_easy_setopt(curl, CURLOPT_URL, url.c_str());
  curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(curl, CURLOPT_FOLLOWLOCATION, 1L);
  curl_easy_setopt(curl, CURLOPT_MAXREDIRS, 5L);
  curl_easy_setopt(curl, CURLOPT_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(curl, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(
      curl, CURLOPT_CONNECTTIMEOUT_MS,
      static_cast<long>(std::min(options.connect_timeout_s, options.total_timeout_s) * 1000.0));
  curl_easy_setopt(curl, CURLOPT_TIMEOUT_MS, static_cast<long>(options.total_timeout_s * 1000.0));
  curl_easy_setopt(curl, CURLOPT_USERAGENT, "pvtwin");
  curl_easy_setopt(curl, CURLOPT_ACCEPT_ENCODING, "");  // whatever curl can decode
  curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, &OnData);
  curl_easy_setopt(curl, CURLOPT_WRITEDATA, &transfer);
  curl_easy_setopt(curl, CURLOPT_XFERINFOFUNCTION, &OnProgress);
  curl_easy_setopt(curl, CURLOPT_XFERINFODATA, &transfer);
  curl_easy_setopt(curl, CURLOPT_NOPROGRESS, 0L);
  curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, error_buffer);
  const CURLcode rc = curl_easy_perform(curl);
  curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &response.status);
  curl_easy_cleanup(curl);
  if (rc != CURLE_OK) {
    response.outcome = transfer.too_large ? HttpResponse::Outcome::kBroken : OutcomeOf(rc);
    response.error = transfer.too_large
                         ? "response body over " + std::to_string(options.max_body_bytes) + " bytes"
                         : (error_buffer[0] != '\0' ? std::string(error_buffer)
                                                    : std::string(curl_easy_strerror(rc)));
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
