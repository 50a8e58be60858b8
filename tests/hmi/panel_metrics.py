"""Measures of the 9-inch panel's rules (STYLE.md, HMI): controls at least 34x34 px, text at least 14 px, contrast
at least 4.5:1 between a control's text and the background it stands on."""
from __future__ import annotations

CONTROL_METRICS = """
    const lum = (c) => { const v = c.match(/[\\d.]+/g).slice(0, 3).map(Number).map((x) => x / 255)
      .map((x) => (x <= 0.03928 ? x / 12.92 : ((x + 0.055) / 1.055) ** 2.4));
      return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; };
    const background = (el) => { for (; el; el = el.parentElement) { const c = getComputedStyle(el).backgroundColor;
      if (!/rgba\\(.*, 0\\)$/.test(c) && c !== 'transparent') return c; } return 'rgb(255, 255, 255)'; };
    return arguments[0].map((id) => { const el = document.getElementById(id), r = el.getBoundingClientRect(),
      s = getComputedStyle(el), a = lum(s.color), b = lum(background(el));
      return [id, r.width, r.height, parseFloat(s.fontSize), (Math.max(a, b) + 0.05) / (Math.min(a, b) + 0.05)]; });"""


def check_controls(b, ids):
    """Touch size, text size and contrast of controls, as the 9-inch panel needs them (STYLE.md, HMI)."""
    for name, w, h, font, contrast in b.driver.execute_script(CONTROL_METRICS, ids):
        assert w >= 34 and h >= 34, (name, w, h)
        assert font >= 14, (name, font)
        assert contrast >= 4.5, (name, contrast)


# Every visible control, text and lamp of the page, measured as the operator meets them. A control is a button, a link,
# a field, or anything else the page made tappable (an alarm row, the alarm banner's text: an onclick of its own). A
# control's touch area is the control with its label when tapping the label works the control (a check box and its
# <label for>). A text's
# contrast is taken with the opacity of its ancestors blended in (a dimmed button reads as dim as it looks). Canvas
# drawings are not in the DOM; the robot view's tests measure their texts themselves.
PAGE_METRICS = """
    const rgba = (c) => { const v = (c.match(/[\\d.]+/g) || ['0', '0', '0', '0']).map(Number);
      return [v[0], v[1], v[2], v.length > 3 ? v[3] : 1]; };
    const lum = (v) => { const l = v.slice(0, 3).map((x) => x / 255)
      .map((x) => (x <= 0.03928 ? x / 12.92 : ((x + 0.055) / 1.055) ** 2.4));
      return 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2]; };
    const mix = (top, under, a) => top.slice(0, 3).map((x, i) => a * x + (1 - a) * under[i]);
    const background = (el) => { for (; el; el = el.parentElement) {
      const c = rgba(getComputedStyle(el).backgroundColor); if (c[3] > 0) return c; } return [255, 255, 255, 1]; };
    const opacity = (el) => { let o = 1;
      for (; el; el = el.parentElement) o *= parseFloat(getComputedStyle(el).opacity); return o; };
    const shown = (el) => { if (!el.getClientRects().length || el.closest('dialog:not([open])')) return false;
      const r = el.getBoundingClientRect(), s = getComputedStyle(el);
      return r.width > 0 && r.height > 0 && s.visibility !== 'hidden'; };
    const name = (el) => el.id || el.dataset.path || el.dataset.status ||
      (el.className && el.className.baseVal !== undefined ? el.className.baseVal : el.className) ||
      el.tagName.toLowerCase();
    const out = { small: [], text: [], contrast: [] };
    const controls = [...document.querySelectorAll('button, a, input, select')];
    for (const el of document.querySelectorAll('*')) if (el.onclick && !controls.includes(el)) controls.push(el);
    for (const el of controls) {
      if (!shown(el) || (arguments[0] && el.closest(arguments[0]))) continue;
      let r = el.getBoundingClientRect();
      const label = el.id && el.type === 'checkbox' && document.querySelector(`label[for="${el.id}"]`);
      if (label) { const l = label.getBoundingClientRect();
        r = { width: Math.max(r.right, l.right) - Math.min(r.left, l.left),
              height: Math.max(r.bottom, l.bottom) - Math.min(r.top, l.top) }; }
      if (r.width < 34 - 0.5 || r.height < 34 - 0.5)
        out.small.push([name(el), Math.round(r.width), Math.round(r.height)]);
    }
    const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    const seen = new Set();
    for (let t = walker.nextNode(); t; t = walker.nextNode()) {
      const el = t.parentElement;
      if (!t.textContent.trim() || seen.has(el) || !el ||
          ['SCRIPT', 'STYLE', 'OPTION', 'NOSCRIPT'].includes(el.tagName)) continue;
      seen.add(el);
      if (!shown(el)) continue;
      const s = getComputedStyle(el), m = el instanceof SVGElement && el.getScreenCTM && el.getScreenCTM();
      const size = parseFloat(s.fontSize) * (m ? Math.hypot(m.a, m.b) : 1);      // an SVG drawing may be scaled
      if (size < 14 - 0.01 && !(arguments[0] && el.closest(arguments[0])))
        out.text.push([name(el), t.textContent.trim().slice(0, 30), size]);
      const under = background(el), svg = el instanceof SVGElement;
      const fg = rgba(svg ? s.fill : s.color), shownFg = mix(mix(fg, under, fg[3]), under, opacity(el));
      const a = lum(shownFg), b = lum(under), ratio = (Math.max(a, b) + 0.05) / (Math.min(a, b) + 0.05);
      if (ratio < 4.5) out.contrast.push([name(el), t.textContent.trim().slice(0, 30), Math.round(ratio * 100) / 100]);
    }
    return out;"""


def page_metrics(b, zoomable: str = "") -> dict:
    """The panel rules' violations on the page shown: {"small": [(name, w, h)], "text": [(name, text, px)],
    "contrast": [(name, text, ratio)]}; all three empty on a page an operator can use. ``zoomable``: a selector of
    drawings with their own zoom keys, whose text size is left out (the operator enlarges them)."""
    return b.driver.execute_script(PAGE_METRICS, zoomable)


# Texts cut by their box: an element whose text is wider (or taller: a line clamp) than its box while it hides the
# overflow (text-overflow: ellipsis or overflow: hidden). ``allowed``: a selector of texts that may be cut because
# the operator has them whole one tap away (the alarm banner's line, an alarm row's text past two lines, the robot's
# error text on Main's tile: each is whole when its alarm is tapped, and in History).
CUT_TEXTS = """
    const out = [];
    const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    const seen = new Set();
    for (let t = walker.nextNode(); t; t = walker.nextNode()) {
      const el = t.parentElement;
      if (!el || !t.textContent.trim() || seen.has(el) || el instanceof SVGElement) continue;
      seen.add(el);
      if (!el.getClientRects().length || el.closest('dialog:not([open])') || (arguments[0] && el.closest(arguments[0])))
        continue;
      const s = getComputedStyle(el);
      if (s.overflowX === 'visible' && s.overflowY === 'visible' && s.textOverflow !== 'ellipsis') continue;
      const range = document.createRange();        // the text's own width, to the sub-pixel (scrollWidth is rounded)
      range.selectNodeContents(el);
      const box = el.getBoundingClientRect().width - parseFloat(s.paddingLeft) - parseFloat(s.paddingRight) -
        parseFloat(s.borderLeftWidth) - parseFloat(s.borderRightWidth);
      if (range.getBoundingClientRect().width > box + 0.01 || el.scrollWidth > el.clientWidth + 1 ||
          (s.overflowY !== 'visible' && s.overflowY !== 'auto' && el.scrollHeight > el.clientHeight + 1))
        out.push([el.id || el.dataset.status || el.className || el.tagName, t.textContent.trim().slice(0, 40)]);
    }
    return out;"""


def cut_texts(b, allowed: str = ".alarm-banner .text, #robot-error, #alarm-history") -> list:
    """Labels and values the page cuts with "…" or hides past their box: [(name, text)]; empty on a page whose every
    label and value an operator needs can be read whole."""
    return b.driver.execute_script(CUT_TEXTS, allowed)
