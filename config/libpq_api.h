// libpq's functions, from libpq.so.5 loaded on first use
// (config/shared_library.h). Callers write Libpq().PQexec(...) where they
// would write PQexec(...); types and constants come from libpq-fe.h.
#pragma once

#include <libpq-fe.h>

namespace pvtwin {

// Every libpq function pvtwin calls. A new call is added here first: the
// loader binds each name in the list, so none can be left unbound.
// clang-format off
#define PVTWIN_LIBPQ_FUNCTIONS(X) \
  X(PQclear) \
  X(PQconnectdb) \
  X(PQconnectdbParams) \
  X(PQconnectPoll) \
  X(PQconnectStartParams) \
  X(PQconsumeInput) \
  X(PQconninfoFree) \
  X(PQconninfoParse) \
  X(PQdb) \
  X(PQerrorMessage) \
  X(PQexec) \
  X(PQexecParams) \
  X(PQfinish) \
  X(PQflush) \
  X(PQfreemem) \
  X(PQgetResult) \
  X(PQgetisnull) \
  X(PQgetvalue) \
  X(PQhost) \
  X(PQisBusy) \
  X(PQnfields) \
  X(PQntuples) \
  X(PQport) \
  X(PQputCopyData) \
  X(PQputCopyEnd) \
  X(PQresultErrorField) \
  X(PQresultErrorMessage) \
  X(PQresultStatus) \
  X(PQsendQuery) \
  X(PQsendQueryParams) \
  X(PQsetNoticeProcessor) \
  X(PQsetnonblocking) \
  X(PQsocket) \
  X(PQstatus)
// clang-format on

struct LibpqApi {
#define PVTWIN_LIBPQ_MEMBER(name) decltype(&::name) name = nullptr;
  PVTWIN_LIBPQ_FUNCTIONS(PVTWIN_LIBPQ_MEMBER)
#undef PVTWIN_LIBPQ_MEMBER
};

// libpq, loaded and bound by the first call (thread-safe); throws
// std::runtime_error when libpq.so.5 is missing (see SharedLibrary).
const LibpqApi& Libpq();

}  // namespace pvtwin
