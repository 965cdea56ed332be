#include "TextCache.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_MODULE_H
#include FT_SYSTEM_H

#include <vtkFreeTypeTools.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace parcelscope::viz::detail {

namespace {

std::atomic<std::size_t> allocations{0};

void* zeroedAlloc(FT_Memory, long size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return std::calloc(1, static_cast<std::size_t>(size));
}

void release(FT_Memory, void* block) { std::free(block); }

void* zeroedRealloc(FT_Memory, long currentSize, long newSize, void* block) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  void* grown = std::realloc(block, static_cast<std::size_t>(newSize));
  if (grown && newSize > currentSize) {
    std::memset(static_cast<char*>(grown) + currentSize, 0, static_cast<std::size_t>(newSize - currentSize));
  }
  return grown;
}

// vtkFreeTypeTools builds its cache manager in a protected member; this
// reaches it through a pointer to that member.
struct CacheAccess : vtkFreeTypeTools {
  static void restart(vtkFreeTypeTools* tools) { (tools->*(&CacheAccess::InitializeCacheManager))(); }
};

}  // namespace

void prepareTextRendering() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkFreeTypeTools* tools = vtkFreeTypeTools::GetInstance();
    FT_Library* library = tools ? tools->GetLibrary() : nullptr;
    if (!library || !*library) return;  // VTK without FreeType text: nothing to do
    // Freed by FreeType (FT_Done_FreeType hands the record to its own free).
    auto* memory = static_cast<FT_MemoryRec_*>(std::malloc(sizeof(FT_MemoryRec_)));
    if (!memory) return;  // text still works, through the cache as it is
    memory->user = nullptr;
    memory->alloc = zeroedAlloc;
    memory->free = release;
    memory->realloc = zeroedRealloc;
    FT_Library fresh = nullptr;
    if (FT_New_Library(memory, &fresh) != 0) {
      std::free(memory);
      return;
    }
    FT_Add_Default_Modules(fresh);
    FT_Set_Default_Properties(fresh);
    const FT_Library old = *library;
    *library = fresh;
    // The cache manager (and any face it opened on the old library) is
    // released and built again on the new library, then the old one goes.
    CacheAccess::restart(tools);
    FT_Done_FreeType(old);
  });
}

std::size_t textAllocations() { return allocations.load(std::memory_order_relaxed); }

}  // namespace parcelscope::viz::detail
