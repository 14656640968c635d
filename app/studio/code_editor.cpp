// code_editor.cpp — see code_editor.h.
#include "app/studio/code_editor.h"

#include <algorithm>
#include <cstdio>

#include <imgui_stdlib.h>

namespace sylva::studio {

namespace {

ImVec2 add(ImVec2 a, ImVec2 b) { return ImVec2(a.x + b.x, a.y + b.y); }

constexpr ImU32 kGutterText = IM_COL32(130, 130, 140, 255);
constexpr ImU32 kCurrentLine = IM_COL32(255, 255, 255, 18);
constexpr ImU32 kErrorRed = IM_COL32(235, 70, 60, 255);
constexpr ImU32 kEditorBg = IM_COL32(22, 24, 28, 255);


}  // namespace

void line_column(const char* text, size_t length, size_t offset, uint32_t* line, uint32_t* column) {
  uint32_t l = 1;
  size_t line_start = 0;
  offset = std::min(offset, length);
  for (size_t i = 0; i < offset; ++i)
    if (text[i] == '\n') ++l, line_start = i + 1;
  *line = l;
  *column = static_cast<uint32_t>(offset - line_start + 1);
}

size_t changed_until(std::string_view before, std::string_view after) {
  const size_t n = std::min(before.size(), after.size());
  size_t prefix = 0;
  while (prefix < n && before[prefix] == after[prefix]) ++prefix;
  size_t suffix = 0;
  while (suffix < n - prefix && before[before.size() - 1 - suffix] == after[after.size() - 1 - suffix]) ++suffix;
  return after.size() - suffix;
}

size_t offset_of(const std::string& text, uint32_t line, uint32_t column) {
  size_t pos = 0;
  for (uint32_t l = 1; l < line; ++l) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) return text.size();
    pos = nl + 1;
  }
  size_t end = text.find('\n', pos);
  if (end == std::string::npos) end = text.size();
  return std::min(end, pos + (column > 0 ? column - 1 : 0));
}

void CodeEditor::jump_to(uint32_t line, uint32_t column, uint32_t select) {
  jump_ = Jump{std::max(1u, line), std::max(1u, column), select};
}

void CodeEditor::replace(const std::string& text) {
  if (active_) replacement_ = text;
}

bool CodeEditor::find_next(const std::string& text, const std::string& query) {
  if (query.empty()) return false;
  // Start after the cursor; a match right at the cursor counts when nothing was found yet.
  size_t from = std::min(cursor_offset_, text.size());
  size_t at = text.find(query, from);
  if (at == from && at != std::string::npos) at = text.find(query, from + 1);
  if (at == std::string::npos) at = text.find(query);
  if (at == std::string::npos) return false;
  uint32_t line, column;
  line_column(text.data(), text.size(), at, &line, &column);
  jump_to(line, column, static_cast<uint32_t>(query.size()));
  cursor_offset_ = at + query.size();
  return true;
}

int CodeEditor::callback(ImGuiInputTextCallbackData* data) {
  return static_cast<CodeEditor*>(data->UserData)->on_callback(data);
}

int CodeEditor::on_callback(ImGuiInputTextCallbackData* data) {
  if (data->EventFlag == ImGuiInputTextFlags_CallbackEdit) {
    changed_ = true;
    return 0;
  }
  if (data->EventFlag != ImGuiInputTextFlags_CallbackAlways) return 0;
  if (replacement_) {
    data->DeleteChars(0, data->BufTextLen);
    data->InsertChars(0, replacement_->c_str(), replacement_->c_str() + replacement_->size());
    replacement_.reset();
    data->CursorPos = std::min(data->CursorPos, data->BufTextLen);
    data->SelectionStart = data->SelectionEnd = data->CursorPos;
  }
  if (jump_) {
    const std::string buf(data->Buf, static_cast<size_t>(data->BufTextLen));
    const size_t at = offset_of(buf, jump_->line, jump_->column);
    const size_t end = std::min(buf.size(), at + jump_->select);
    data->SelectionStart = static_cast<int>(at);
    data->SelectionEnd = static_cast<int>(end);
    data->CursorPos = static_cast<int>(end);
    jump_.reset();
    scroll_to_cursor_ = true;
  }
  cursor_offset_ = static_cast<size_t>(data->CursorPos);
  line_column(data->Buf, static_cast<size_t>(data->BufTextLen), cursor_offset_, &cursor_line_, &cursor_column_);
  if (cursor_offset_ != last_cursor_offset_) scroll_to_cursor_ = true;
  last_cursor_offset_ = cursor_offset_;
  return 0;
}

void CodeEditor::draw_bars(std::string& text) {
  const int escape = ImGui::GetKeyIndex(ImGuiKey_Escape);
  if (find_open_) {
    ImGui::TextUnformatted("Find");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(std::max(80.0f, ImGui::GetContentRegionAvail().x - 140));
    if (focus_bar_) ImGui::SetKeyboardFocusHere(), focus_bar_ = false;
    bool go = ImGui::InputText("##find", &find_query_, ImGuiInputTextFlags_EnterReturnsTrue);
    if (go) ImGui::SetKeyboardFocusHere(-1);  // keep typing / pressing Enter in the box
    const bool bar_active = ImGui::IsItemActive();
    ImGui::SameLine();
    go |= ImGui::Button("Next");
    if (go) find_failed_ = !find_next(text, find_query_);
    ImGui::SameLine();
    if (ImGui::Button("Close##find") || (bar_active && ImGui::IsKeyPressed(escape))) find_open_ = false;
    if (find_failed_) {
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(0.95f, 0.45f, 0.4f, 1), "not found");
    }
  }
  if (goto_open_) {
    ImGui::TextUnformatted("Go to line");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(120);
    if (focus_bar_) ImGui::SetKeyboardFocusHere(), focus_bar_ = false;
    const bool go = ImGui::InputInt("##goto", &goto_line_, 0, 0, ImGuiInputTextFlags_EnterReturnsTrue);
    const bool bar_active = ImGui::IsItemActive();
    ImGui::SameLine();
    if (go || ImGui::Button("Go")) {
      jump_to(static_cast<uint32_t>(std::max(1, goto_line_)), 1);
      goto_open_ = false;
    }
    ImGui::SameLine();
    if (ImGui::Button("Close##goto") || (bar_active && ImGui::IsKeyPressed(escape))) goto_open_ = false;
  }
}

bool CodeEditor::draw(const char* id, std::string& text, const std::optional<EditorMark>& mark, ImVec2 size) {
  changed_ = false;
  marker_drawn_ = false;
  ImGui::PushID(id);
  const ImVec2 bars_start = ImGui::GetCursorPos();
  draw_bars(text);
  size.y -= ImGui::GetCursorPos().y - bars_start.y;
  ImGui::PushStyleColor(ImGuiCol_ChildBg, kEditorBg);
  ImGui::BeginChild("code", size, false, ImGuiWindowFlags_HorizontalScrollbar);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImGuiStyle& style = ImGui::GetStyle();
  const float lh = ImGui::GetFontSize();
  line_height_ = lh;

  // Lines, and the widest one (the widget is made as wide as its content).
  uint32_t lines = 1;
  float widest = 0;
  for (size_t start = 0;;) {
    size_t nl = text.find('\n', start);
    const size_t end = nl == std::string::npos ? text.size() : nl;
    widest = std::max(widest, ImGui::CalcTextSize(text.data() + start, text.data() + end).x);
    if (nl == std::string::npos) break;
    ++lines;
    start = nl + 1;
  }
  char digits[16];
  std::snprintf(digits, sizeof digits, "%u", lines);
  const float gutter = ImGui::CalcTextSize(digits).x + lh * 1.6f;
  const ImVec2 start = ImGui::GetCursorScreenPos();
  const float height = static_cast<float>(lines) * lh + 2 * style.FramePadding.y + lh;
  const float width = std::max(ImGui::GetContentRegionAvail().x - gutter, widest + 2 * style.FramePadding.x + lh);

  ImGui::SetCursorScreenPos(ImVec2(start.x + gutter, start.y));
  if (jump_ && !active_) ImGui::SetKeyboardFocusHere();
  ImGui::PushStyleColor(ImGuiCol_FrameBg, IM_COL32(0, 0, 0, 0));
  text_ = &text;
  ImGui::InputTextMultiline("##text", &text, ImVec2(width, height),
                            ImGuiInputTextFlags_AllowTabInput | ImGuiInputTextFlags_CallbackAlways |
                                ImGuiInputTextFlags_CallbackEdit,
                            &CodeEditor::callback, this);
  text_ = nullptr;
  ImGui::PopStyleColor();
  active_ = ImGui::IsItemActive();
  deactivated_ = was_active_ && !active_;
  was_active_ = active_;
  if (!active_) replacement_.reset();
  const ImVec2 item_min = ImGui::GetItemRectMin();
  text_origin_ = add(item_min, style.FramePadding);
  const float window_left = ImGui::GetWindowPos().x, window_right = window_left + ImGui::GetWindowWidth();

  // The current line's band (under the text: the widget draws in its own child window,
  // after this one).
  if (active_) {
    const float y = text_origin_.y + static_cast<float>(cursor_line_ - 1) * lh;
    dl->AddRectFilled(ImVec2(window_left, y), ImVec2(window_right, y + lh), kCurrentLine);
  }
  // Gutter: line numbers, right-aligned, at the editor's left edge whatever the sideways
  // scroll (issue 31 §5: it scrolled away with long lines). Where the text has scrolled
  // under it, it is drawn over the text — which draws in its own child window, after this
  // one — on the foreground list clipped to the editor (in place while a popup is open,
  // which that list would cover).
  const float clip_top = ImGui::GetWindowPos().y, clip_bottom = clip_top + ImGui::GetWindowHeight();
  scroll_x_ = ImGui::GetScrollX();
  left_edge_ = window_left;
  gutter_left_ = start.x + scroll_x_;
  ImDrawList* gutter_dl = dl;
  if (scroll_x_ > 0 && !ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId)) {
    gutter_dl = ImGui::GetForegroundDrawList();
    gutter_dl->PushClipRect(ImVec2(window_left, clip_top), ImVec2(window_right, clip_bottom), true);
    gutter_dl->AddRectFilled(ImVec2(gutter_left_, clip_top), ImVec2(gutter_left_ + gutter, clip_bottom), kEditorBg);
  }
  for (uint32_t l = 1; l <= lines; ++l) {
    const float y = text_origin_.y + static_cast<float>(l - 1) * lh;
    if (y + lh < clip_top || y > clip_bottom) continue;
    char number[16];
    std::snprintf(number, sizeof number, "%u", l);
    const float w = ImGui::CalcTextSize(number).x;
    gutter_dl->AddText(ImVec2(gutter_left_ + gutter - lh * 0.6f - w, y),
                       active_ && l == cursor_line_ ? IM_COL32(220, 220, 225, 255) : kGutterText, number);
  }
  // The error: a dot in the gutter and a squiggle under its columns.
  if (mark && mark->line >= 1 && mark->line <= lines) {
    const float y = text_origin_.y + static_cast<float>(mark->line - 1) * lh;
    const float r = lh * 0.28f;
    gutter_dl->AddCircleFilled(ImVec2(gutter_left_ + r + 2, y + lh * 0.5f), r, kErrorRed);
    marker_drawn_ = true;
    marker_line_ = mark->line;
    const size_t line_begin = offset_of(text, mark->line, 1);
    size_t line_end = text.find('\n', line_begin);
    if (line_end == std::string::npos) line_end = text.size();
    size_t a = line_begin, b = line_end;
    if (mark->column > 0) {
      a = std::min(line_end, line_begin + mark->column - 1);
      b = std::min(line_end, a + std::max(1u, mark->length));
    }
    float x0 = text_origin_.x + ImGui::CalcTextSize(text.data() + line_begin, text.data() + a).x;
    float x1 = x0 + ImGui::CalcTextSize(text.data() + a, text.data() + b).x;
    if (x1 - x0 < lh * 0.6f) x1 = x0 + lh * 0.6f;
    const float base = y + lh - 1, amp = lh * 0.12f, step = lh * 0.25f;
    for (float x = x0; x < x1; x += step) {
      const float xn = std::min(x1, x + step);
      const bool up = static_cast<int>((x - x0) / step) % 2 == 0;
      dl->AddLine(ImVec2(x, up ? base : base - amp), ImVec2(xn, up ? base - amp : base), kErrorRed, 1.2f);
    }
    if (!mark->message.empty() && (ImGui::IsMouseHoveringRect(ImVec2(x0, y), ImVec2(x1, y + lh)) ||
                                   ImGui::IsMouseHoveringRect(ImVec2(gutter_left_, y),
                                                              ImVec2(gutter_left_ + gutter, y + lh))))
      ImGui::SetTooltip("%s", mark->message.c_str());
  }
  if (gutter_dl != dl) gutter_dl->PopClipRect();
  // Keep the cursor's line in view when it moved (keys, jumps), not when the user scrolls.
  if (scroll_to_cursor_) {
    scroll_to_cursor_ = false;
    const float content_top = start.y - ImGui::GetWindowPos().y + ImGui::GetScrollY();
    const float cy = content_top + style.FramePadding.y + static_cast<float>(cursor_line_ - 1) * lh;
    const float view = ImGui::GetWindowHeight() - style.ScrollbarSize;
    if (cy < ImGui::GetScrollY()) ImGui::SetScrollY(std::max(0.0f, cy - lh));
    else if (cy + lh > ImGui::GetScrollY() + view) ImGui::SetScrollY(cy + 2 * lh - view);
    // Sideways too: the cursor's column stays right of the gutter and inside the view.
    const size_t line_begin = offset_of(text, cursor_line_, 1);
    const float cx = gutter + style.FramePadding.x +
                     ImGui::CalcTextSize(text.data() + line_begin,
                                         text.data() + std::min(text.size(), line_begin + cursor_column_ - 1)).x;
    const float window_w = ImGui::GetWindowWidth();
    if (cx < ImGui::GetScrollX() + gutter) ImGui::SetScrollX(std::max(0.0f, cx - gutter - lh));
    else if (cx > ImGui::GetScrollX() + window_w - lh) ImGui::SetScrollX(cx - window_w + 2 * lh);
  }
  ImGui::EndChild();
  ImGui::PopStyleColor();
  ImGui::PopID();
  return changed_;
}

}  // namespace sylva::studio
