#include "core/image/StrictJpeg.h"

#include "core/image/LinearImageHeader.h"

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <jpeglib.h>

namespace mirage {

namespace {

struct StrictErrorManager {
    jpeg_error_mgr pub;  // first member: libjpeg casts the pointer back
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

extern "C" void strictErrorExit(j_common_ptr cinfo) {
    auto* err = reinterpret_cast<StrictErrorManager*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, err->message);
    std::longjmp(err->jump, 1);
}

// Level -1 is a warning about corrupt data; treated like an error. Trace messages (>= 1) are
// ignored.
extern "C" void strictEmitMessage(j_common_ptr cinfo, int level) {
    if (level < 0) strictErrorExit(cinfo);
}

// The libjpeg part: no C++ object with a destructor lives across setjmp/longjmp here.
bool decodeInto(const uint8_t* data, size_t size, cv::Mat& out, char* message) {
    jpeg_decompress_struct cinfo;
    StrictErrorManager err;
    cinfo.err = jpeg_std_error(&err.pub);
    err.pub.error_exit = strictErrorExit;
    err.pub.emit_message = strictEmitMessage;
    err.message[0] = '\0';
    if (setjmp(err.jump)) {
        std::snprintf(message, JMSG_LENGTH_MAX, "%s", err.message);
        jpeg_destroy_decompress(&cinfo);
        return false;
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    if (cinfo.image_width < 1 || cinfo.image_height < 1 || cinfo.image_width > kMaxJpegSide ||
        cinfo.image_height > kMaxJpegSide) {
        std::snprintf(message, JMSG_LENGTH_MAX, "image size %ux%u outside 1..%d", cinfo.image_width,
                      cinfo.image_height, kMaxJpegSide);
        jpeg_destroy_decompress(&cinfo);
        return false;
    }
    cinfo.out_color_space = JCS_EXT_BGR;
    jpeg_start_decompress(&cinfo);
    out.create(int(cinfo.output_height), int(cinfo.output_width), CV_8UC3);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = out.ptr<uchar>(int(cinfo.output_scanline));
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);  // reads to EOI: warns about data that is cut or left over
    jpeg_destroy_decompress(&cinfo);
    return true;
}

}  // namespace

cv::Mat decodeJpegStrict(const uint8_t* data, size_t size, std::string* problem) {
    if (data == nullptr || size < 4) {
        if (problem) *problem = "no JPEG data";
        return {};
    }
    cv::Mat out;
    char message[JMSG_LENGTH_MAX] = {0};
    if (!decodeInto(data, size, out, message)) {
        if (problem) *problem = std::string("corrupt JPEG (") + message + ")";
        return {};
    }
    return out;
}

cv::Mat readImageStrict(const std::filesystem::path& path, std::string* problem) {
    auto fail = [&](const std::string& why) {
        if (problem) *problem = why;
        return cv::Mat();
    };
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail("cannot open the file");
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto data = [&] { return reinterpret_cast<const uint8_t*>(bytes.data()); };
    // The size from the header first: the decoders allocate whatever it asks for.
    if (const std::string tooLarge = encodedImageSizeProblem(bytes); !tooLarge.empty())
        return fail(tooLarge);
    if (bytes.size() >= 3 && std::memcmp(bytes.data(), "\xFF\xD8\xFF", 3) == 0)
        return decodeJpegStrict(data(), bytes.size(), problem);
    static const char kPngMagic[] = "\x89PNG\r\n\x1a\n";
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngMagic, 8) == 0) {
        // The IEND chunk: zero length, type, CRC (bytes after it are tolerated).
        const size_t iend = bytes.rfind(std::string("\0\0\0\0IEND", 8));
        if (iend == std::string::npos || iend < 8 || iend + 12 > bytes.size())
            return fail("truncated PNG (no IEND chunk at its end; cut short?)");
    }
    cv::Mat img;
    try {
        img = cv::imdecode(std::vector<uint8_t>(bytes.begin(), bytes.end()), cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
        return fail(std::string("cannot decode the image: ") + e.err);
    }
    if (img.empty()) return fail("cannot decode the image (corrupt or unsupported format)");
    return img;
}

}  // namespace mirage
