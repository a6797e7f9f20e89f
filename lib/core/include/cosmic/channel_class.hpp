// The real-time class of a channel (COSMIC section 4): hard, soft or non real-time. Its own header
// so that the event views (cosmic/event.hpp) can name it without the whole model.
#pragma once

namespace cosmic {

enum class ChannelClass { hrt, srt, nrt };

}  // namespace cosmic
