"""Measures of the 9-inch panel's rules (STYLE.md, HMI): controls at least 34x34 px, text at least 14 px, contrast
at least 4.5:1 between a control's text and the background it stands on."""
from __future__ import annotations


CONTROL_METRICS = """
    const lum = (c) => { const v = c.match(/[\\d.]+/g).slice(0, 3).map(Number).map((x) => x / 255)
      .map((x) => (x <= 0.03928 ? x / 12.92 : ((x + 0.055) / 1.055) ** 2.4)); return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; };
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
