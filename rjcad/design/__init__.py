"""The design stage, pure numbers: a joint's validated parameters and derived dimensions (params), the wound
springs' reach (envelope), the desktop layout's sizes (layout_desktop), a finger's template (finger_params) and
its shortest links (finger_lengths). No CAD kernel."""
