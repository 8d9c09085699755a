# Every field and constant name in DIR/*.lcm must be usable in every language
# lcm-gen targets: not a reserved word of C, C++, Java, Python, Lua, C# or Go
# (e.g. `lambda` is a Python keyword, `event` a C# one).
#   cmake -DDIR=msgs -P check_msg_names.cmake
set(_kw
  # C / C++
  alignas alignof and and_eq asm auto bitand bitor bool break case catch char char8_t char16_t char32_t
  class compl concept const consteval constexpr constinit const_cast continue co_await co_return co_yield
  decltype default delete do double dynamic_cast else enum explicit export extern false float for friend
  goto if inline int long mutable namespace new noexcept not not_eq nullptr operator or or_eq private
  protected public register reinterpret_cast requires restrict return short signed sizeof static
  static_assert static_cast struct switch template this thread_local throw true try typedef typeid
  typename union unsigned using virtual void volatile wchar_t while xor xor_eq
  # Java
  abstract assert boolean byte extends final finally implements import instanceof interface native
  package strictfp super synchronized throws transient var yield record sealed permits
  # Python
  False None True as async await def del elif except global in is lambda nonlocal pass raise with
  # Lua
  elseif end function local nil repeat then until
  # C#
  base checked decimal delegate event fixed foreach implicit internal lock object out override params
  readonly ref sbyte stackalloc string uint ulong unchecked unsafe ushort
  # Go
  chan defer fallthrough func go map range select type)
file(GLOB _files ${DIR}/*.lcm)
if(NOT _files)
  message(FATAL_ERROR "no .lcm files in ${DIR}")
endif()
set(_bad "")
set(_count 0)
foreach(f IN LISTS _files)
  file(STRINGS ${f} _lines)
  foreach(line IN LISTS _lines)
    string(REGEX REPLACE "//.*" "" line "${line}")
    if(line MATCHES "^[ \t]*(const[ \t]+)?[A-Za-z_][A-Za-z0-9_]*[ \t]+([A-Za-z_][A-Za-z0-9_]*)[ \t]*(\\[[^]]*\\])?[ \t]*(=|;)")
      set(_name ${CMAKE_MATCH_2})
      math(EXPR _count "${_count} + 1")
      list(FIND _kw ${_name} _i)
      if(NOT _i EQUAL -1)
        list(APPEND _bad "${f}: `${_name}` is a reserved word")
      endif()
    endif()
  endforeach()
endforeach()
if(_bad)
  string(REPLACE ";" "\n" _bad "${_bad}")
  message(FATAL_ERROR "${_bad}")
endif()
message(STATUS "${_count} field/constant names checked, none reserved")
