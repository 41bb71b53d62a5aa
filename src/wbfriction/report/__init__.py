"""What a person sees: the report gathered (:mod:`.build`) and rendered as one self-contained HTML
page (:mod:`.html`), and the figures of the report and the thesis's studies (:mod:`.figures`).

Import the modules themselves (``from wbfriction.report.build import make_report``): this
package does not import matplotlib until a figure is wanted."""
