# cmake -DIN=page.html -DOUT=page.cc -P embed_page.cmake: the page as a C++ string.
file(READ ${IN} html)
string(FIND "${html}" ")MAPLESS_PAGE\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${IN} contains the raw string's delimiter")
endif()
file(WRITE ${OUT} "// Generated from page.html by embed_page.cmake.\n#include \"mapless/live/live_view.h\"\n\nnamespace mapless::live {\n\nconst std::string& LivePage() {\n  static const std::string page = R\"MAPLESS_PAGE(${html})MAPLESS_PAGE\";\n  return page;\n}\n\n}  // namespace mapless::live\n")
