// code_editor.h — the studio's grammar editor (docs/spec/studio.md "Editor") on Dear ImGui 1.86's
// InputTextMultiline: ImGui has no code editor and Debian packages none, so the editor is
// built around ImGui's own text widget. The text widget is given the full
// height of its content inside a scrolling child, so it never scrolls itself and
// everything drawn beside it on the child's draw list — the gutter's line numbers and
// error marker, the squiggle under the error's columns, the current line's band —
// scrolls with the text for free. The widget's frame is transparent so the band and
// squiggle drawn under it show.
//
// Jumps (to an error, a find match, a line) go through the widget's CallbackAlways,
// the one place where an active InputText lets its cursor be set; the widget is focused
// first, since callbacks run only while it is active. The same callback replaces the
// whole text when the document changes under an active widget (undo), which the widget
// would otherwise overwrite with its own copy.
//
// The widget's own undo (Ctrl+Z/Ctrl+Y inside stb_textedit) is not used: the studio
// unmaps those keys and keeps whole-document undo (undo_history.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <imgui.h>

namespace sylva::studio {

// An error to show in the text: 1-based line, 1-based byte column (0: the whole line).
struct EditorMark {
  uint32_t line = 0;
  uint32_t column = 0;
  uint32_t length = 1;   // bytes underlined
  std::string message;   // tooltip
};

// Line (1-based) and column (1-based, bytes) of byte `offset` of `text`.
void line_column(const char* text, size_t length, size_t offset, uint32_t* line, uint32_t* column);

// Where an edit that turned `before` into `after` ends in `after` (bytes): after their
// common prefix and before their common suffix. An undo puts the cursor there.
size_t changed_until(std::string_view before, std::string_view after);

class CodeEditor {
 public:
  // Draws the editor (find / go-to bar when open, then the text) filling `size`.
  // Returns true when the user changed `text` this frame.
  bool draw(const char* id, std::string& text, const std::optional<EditorMark>& mark, ImVec2 size);

  // Moves the cursor to line:column (1-based, bytes), selecting `select` bytes, on the
  // next frames (focusing the widget); the line is scrolled into view.
  void jump_to(uint32_t line, uint32_t column, uint32_t select = 0);
  // Replaces the text shown with `text` (an undo or a reload): safe while the widget is
  // active. The caller's string must be set to the same text.
  void replace(const std::string& text);
  void open_find() { find_open_ = true, focus_bar_ = true, goto_open_ = false; }
  void open_goto() { goto_open_ = true, focus_bar_ = true, find_open_ = false; }
  // Selects the next occurrence of `query` after the cursor (wrapping); false if none.
  bool find_next(const std::string& text, const std::string& query);

  uint32_t cursor_line() const { return cursor_line_; }     // 1-based
  uint32_t cursor_column() const { return cursor_column_; } // 1-based, bytes
  size_t cursor_offset() const { return cursor_offset_; }
  bool active() const { return active_; }                  // the text widget has focus
  bool deactivated() const { return deactivated_; }        // it lost focus this frame
  bool jump_pending() const { return jump_.has_value(); }
  // Where the text's first line starts on screen (tests click relative to it).
  ImVec2 text_origin() const { return text_origin_; }
  float line_height() const { return line_height_; }
  bool marker_drawn() const { return marker_drawn_; }      // the error marker was drawn last frame
  // Where the gutter (line numbers, error dot) was drawn last frame, on screen, and how far
  // the text was scrolled sideways: the gutter stays at the editor's left edge.
  float gutter_left() const { return gutter_left_; }
  float scroll_x() const { return scroll_x_; }
  float left_edge() const { return left_edge_; }  // the editor's left edge on screen
  uint32_t marker_line() const { return marker_line_; }

 private:
  static int callback(ImGuiInputTextCallbackData* data);
  int on_callback(ImGuiInputTextCallbackData* data);
  void draw_bars(std::string& text);

  struct Jump {
    uint32_t line, column, select;
  };
  std::optional<Jump> jump_;
  std::optional<std::string> replacement_;
  bool scroll_to_cursor_ = false;
  bool changed_ = false;
  bool active_ = false, was_active_ = false, deactivated_ = false;
  bool find_open_ = false, goto_open_ = false, focus_bar_ = false;
  std::string find_query_;
  int goto_line_ = 1;
  bool find_failed_ = false;
  uint32_t cursor_line_ = 1, cursor_column_ = 1;
  size_t cursor_offset_ = 0;
  size_t last_cursor_offset_ = static_cast<size_t>(-1);
  ImVec2 text_origin_{0, 0};
  float line_height_ = 13;
  bool marker_drawn_ = false;
  float gutter_left_ = 0, scroll_x_ = 0, left_edge_ = 0;
  uint32_t marker_line_ = 0;
  const std::string* text_ = nullptr;  // during draw, for the callback
};

// The byte offset of line:column (1-based) in `text`, clamped to the line's end.
size_t offset_of(const std::string& text, uint32_t line, uint32_t column);

}  // namespace sylva::studio
