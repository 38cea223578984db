//! The one style sheet of the report's pages: the report and the sweep's
//! own page.

pub(super) const STYLE: &str = "body{font-family:system-ui,sans-serif;max-width:72em;margin:2em auto;\
padding:0 1em;line-height:1.45;color:#222}h2{margin-top:2.5em;border-bottom:1px solid #ddd}\
table{border-collapse:collapse;margin:0.5em 0;font-size:90%}td,th{border:1px solid #bbb;\
padding:2px 8px;text-align:right;white-space:nowrap}th{background:#f3f3f3}\
caption{font-weight:bold;text-align:left;white-space:normal;padding:0.3em 0}\
.table-scroll{overflow-x:auto;max-width:100%}.meta{color:#666;font-size:85%}\
td.good,span.good,.item.good{background:#e3f4e3}td.bad,span.bad,.item.bad{background:#f8d7d3}\
td.warn,span.warn{background:#fcf0cc}td.na,span.na{color:#888}\
figure{margin:1em 0}figure.row{display:flex;flex-wrap:wrap;gap:8px}\
figure.row figcaption{flex-basis:100%}figure.row img{width:min(32%,400px);height:auto;\
image-rendering:pixelated}img.plot{width:min(100%,640px)}figcaption{font-size:90%;color:#333}\
nav ol{columns:2}.summary .items{display:flex;flex-wrap:wrap;gap:8px}\
.item{display:block;border:1px solid #ccc;border-radius:4px;padding:4px 8px;min-width:9em;\
max-width:16em;color:inherit;text-decoration:none}.item .value{display:block;font-size:140%;\
font-weight:bold}.item .label{display:block;font-size:80%;color:#444}";
